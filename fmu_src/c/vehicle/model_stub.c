/*
 * The interface-only twin of model.c, for benchmarks/fmu_step.py: the same FMI API
 * (fmi2_api.c) and variables, no model -- every step succeeds at once and every output
 * is 0.  What a host spends per step on an FMU that does nothing.
 */
#include <stdio.h>
#include <string.h>

#include "model.h"

void model_reset(ModelInstance *c)
{
    memset(&c->s, 0, sizeof c->s);
    snprintf(c->s.preset, sizeof c->s.preset, "%s", LCV_DEFAULT_PRESET);
    c->s.phase = PhaseInstantiated;
    c->s.vehicle = -1;
}

int model_exit_initialization(ModelInstance *c) { c->s.vehicle = 0; return 0; }

int model_do_step(ModelInstance *c, double h) { c->s.time += h; return 0; }

int model_get_real(ModelInstance *c, const unsigned vr[], size_t nvr, double value[])
{
    (void)c; (void)vr;
    for (size_t i = 0; i < nvr; ++i) value[i] = 0.0;
    return 0;
}

int model_set_real(ModelInstance *c, unsigned vr, double value)
{
    if (vr >= LCV_FIRST_INPUT && vr < LCV_FIRST_INPUT + LCV_N_INPUTS) c->s.w[vr - LCV_FIRST_INPUT] = value;
    return 0;
}

int model_get_string(ModelInstance *c, unsigned vr, const char **value)
{
    (void)vr;
    *value = c->s.preset;
    return 0;
}

int model_set_string(ModelInstance *c, unsigned vr, const char *value)
{
    (void)vr;
    snprintf(c->s.preset, sizeof c->s.preset, "%s", value ? value : "");
    return 0;
}

int model_get_integer(ModelInstance *c, unsigned vr, int *value) { (void)c; (void)vr; *value = 1; return 0; }

int model_set_integer(ModelInstance *c, unsigned vr, long long value)
{ (void)c; (void)vr; (void)value; return 0; }

int model_check_state(ModelInstance *c, const ModelState *s) { (void)c; (void)s; return 0; }

void model_state_restored(ModelInstance *c, const ModelState *before) { (void)c; (void)before; }

void model_get_nominals(ModelInstance *c, double x[], size_t nx) { (void)c; for (size_t i = 0; i < nx; ++i) x[i] = 1.0; }
void model_get_states(ModelInstance *c, double x[], size_t nx) { (void)c; for (size_t i = 0; i < nx; ++i) x[i] = 0.0; }

void model_set_states(ModelInstance *c, const double x[], size_t nx) { (void)c; (void)x; (void)nx; }

int model_derivatives(ModelInstance *c, double dx[], size_t nx)
{
    (void)c;
    for (size_t i = 0; i < nx; ++i) dx[i] = 0.0;
    return 0;
}

const char *model_variable_name(unsigned vr) { (void)vr; return "?"; }

unsigned model_me_state_vr(size_t k) { (void)k; return 0u; }

int model_directional(ModelInstance *c, const unsigned unknowns[], size_t nu, const unsigned knowns[], size_t nk,
                      const double seed[], double out[])
{
    (void)c; (void)unknowns; (void)knowns; (void)nk; (void)seed;
    for (size_t i = 0; i < nu; ++i) out[i] = 0.0;
    return 0;
}
