/*
 * The vehicle model behind the native FMUs: what the FMI API files (api/fmi2_api.c,
 * api/fmi3_api.c) call, FMI-neutral (no FMI type: the API files hold what is FMI's -- the
 * host's callbacks, the status codes -- and name the FMI function in their messages).  The
 * model (parameters, clamping, checks, exact steps, outputs) is in model.c, the linear
 * algebra in linalg.c.  config.h (the interface table: the ValueReference enum, sizes,
 * ranges) and vehicle_data.h (the matrices of the vehicle or the six presets) are generated
 * by lcvreport.fmu.build.
 */
#ifndef LCV_MODEL_H
#define LCV_MODEL_H

#include <stddef.h>

#include "fmu_common.h"
#include "config.h"

/* Everything that evolves: copied by GetFMUState and serialized as bytes. */
typedef struct {
    char preset[64];                    /* preset name (preset FMU) */
    double tire_scale, u_min;           /* fixed parameters */
    double w[LCV_N_INPUTS];             /* inputs, SI, interface order (u first) */
    double z[LCV_MAX_M];                /* [x, psi1, Y1], SI */
    double time, last_speed;            /* [s], speed of the last step [m/s] */
    int clamped;                        /* u below u_min at the last step */
    int phase;                          /* Phase */
    int vehicle;                        /* index into LCV_VEHICLES, -1 before initialization */
    char error[1024];                   /* why the instance is in PhaseError */
    double crossfall;                   /* fixed parameter [%] */
    int model_exchange;                 /* written by a Model Exchange instance (1) or a Co-Simulation one (0) */
} ModelState;

typedef struct {
    int valid;
    double u, h;
    unsigned long stamp;
    double K[LCV_MAX_M * (LCV_MAX_M + LCV_N_INPUTS)];   /* [Ad, Gd Bw] row-major, ld = m + NW */
    double gc[LCV_MAX_M];                               /* Gd Fc: the crossfall's share of a step */
} StepEntry;

typedef struct {
    int valid;
    double u;
    unsigned long stamp;
    double A[LCV_MAX_STATES * LCV_MAX_STATES];          /* M^-1 S */
    double Ca[LCV_MAX_FD * LCV_MAX_STATES];             /* feedthrough rows (ay, extras): Ca x + DaB w + daF */
    double DaB[LCV_MAX_FD * LCV_N_INPUTS];
    double daF[LCV_MAX_FD];                             /* the crossfall's part */
    int eig_state;                                      /* 0 not computed, 1 ok, -1 failed */
    double eig;                                         /* max real part [1/s] */
} SpeedEntry;

#define LCV_N_STEP_CACHE 16
#define LCV_N_SPEED_CACHE 16

typedef struct ModelInstance {
    char *name;
    int logging_on;
    int model_exchange;                                  /* instantiated for Model Exchange */
    ModelState s;
    double Bw[LCV_MAX_STATES * LCV_N_INPUTS];            /* generalized force per SI input, tire-scaled */
    double Fc[LCV_MAX_STATES];                           /* the crossfall's constant generalized force */
    StepEntry steps[LCV_N_STEP_CACHE];
    SpeedEntry speeds[LCV_N_SPEED_CACHE];
    unsigned long clock;
    double work[LCV_WORK];                               /* workspace of the linear algebra */
    char msg[1024];                                      /* message of the last warning or error */
} ModelInstance;

/* names of variables and of the Model Exchange states (for messages) */
const char *model_variable_name(unsigned vr);
#define LCV_VARIABLE_NAME(vr) model_variable_name(vr)
unsigned model_me_state_vr(size_t k);
#define LCV_ME_STATE_VR_OF(k) model_me_state_vr(k)

/* the model API: 0 on success, 1 success with a warning in c->msg, -1 error in c->msg */
void model_reset(ModelInstance *c);
int model_exit_initialization(ModelInstance *c);
int model_do_step(ModelInstance *c, double h);
int model_get_real(ModelInstance *c, const unsigned vr[], size_t nvr, double value[]);
int model_set_real(ModelInstance *c, unsigned vr, double value);
int model_get_string(ModelInstance *c, unsigned vr, const char **value);
int model_set_string(ModelInstance *c, unsigned vr, const char *value);
int model_get_integer(ModelInstance *c, unsigned vr, int *value);
int model_set_integer(ModelInstance *c, unsigned vr, long long value);
/* Model Exchange (SPEC section 15): the continuous states of the interface (v1, r.., theta..,
   psi1, Y1; 0 for what the vehicle lacks) and their derivatives at the current inputs */
void model_get_states(ModelInstance *c, double x[], size_t nx);
/* their nominals: each state's physical scale (the peak of the standard single sine), for a host's tolerances */
void model_get_nominals(ModelInstance *c, double x[], size_t nx);
void model_set_states(ModelInstance *c, const double x[], size_t nx);
int model_derivatives(ModelInstance *c, double dx[], size_t nx);
/* directional derivatives of derivatives and outputs with respect to states and inputs other than u */
int model_directional(ModelInstance *c, const unsigned unknowns[], size_t nu, const unsigned knowns[], size_t nk,
                      const double seed[], double out[]);
/* 0 if a snapshot is acceptable for this instance, else -1 with c->msg */
int model_check_state(ModelInstance *c, const ModelState *s);
/* after a snapshot was restored over the state ``before``: drop the caches if the vehicle, the
   tire scale or the crossfall changed */
void model_state_restored(ModelInstance *c, const ModelState *before);

#endif
