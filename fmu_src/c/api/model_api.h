/*
 * What the FMI API files (fmi2_api.c, fmi3_api.c) ask of a model, FMI-neutral: each model's
 * model.h (vehicle/, driver/) defines ModelState and ModelInstance, then includes this file.
 *
 * ModelInstance has at least: char *name; int logging_on; int model_exchange; ModelState s;
 * char msg[]  (the message of the last warning or error);  ModelState at least: int phase
 * (Phase, fmu_common.h); double time; char error[]  (why the instance is in PhaseError).  An FMU
 * state is a copy of the ModelState.  The model's config header defines LCV_GUID,
 * LCV_MODEL_IDENTIFIER_TEXT, LCV_N_ME_STATES, and the model's header LCV_VARIABLE_NAME(vr) and
 * LCV_ME_STATE_VR_OF(k) (names for messages).
 *
 * Every function returns 0 on success, 1 on success with a warning in c->msg, -1 on an error in
 * c->msg (which names no FMI function: the API file prefixes its own).
 */
#ifndef LCV_MODEL_API_H
#define LCV_MODEL_API_H

#include <stddef.h>

void model_reset(ModelInstance *c);
int model_exit_initialization(ModelInstance *c);
int model_do_step(ModelInstance *c, double h);
int model_get_real(ModelInstance *c, const unsigned vr[], size_t nvr, double value[]);
int model_set_real(ModelInstance *c, unsigned vr, double value);
int model_get_string(ModelInstance *c, unsigned vr, const char **value);
int model_set_string(ModelInstance *c, unsigned vr, const char *value);
int model_get_integer(ModelInstance *c, unsigned vr, int *value);
int model_set_integer(ModelInstance *c, unsigned vr, long long value);
/* Model Exchange: the continuous states, their nominals (each state's physical scale, for a host's
   tolerances) and their derivatives at the current inputs */
void model_get_states(ModelInstance *c, double x[], size_t nx);
void model_get_nominals(ModelInstance *c, double x[], size_t nx);
void model_set_states(ModelInstance *c, const double x[], size_t nx);
int model_derivatives(ModelInstance *c, double dx[], size_t nx);
/* directional derivatives of derivatives and outputs with respect to states and inputs */
int model_directional(ModelInstance *c, const unsigned unknowns[], size_t nu, const unsigned knowns[], size_t nk,
                      const double seed[], double out[]);
/* 0 if an FMU state is acceptable for this instance, else -1 with c->msg */
int model_check_state(ModelInstance *c, const ModelState *s);
/* after an FMU state was restored over the state ``before`` (caches to drop) */
void model_state_restored(ModelInstance *c, const ModelState *before);

#endif
