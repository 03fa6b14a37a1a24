/*
 * A path-following driver as a model behind the FMI 2.0 API of this tree (api/fmi2_api.c:
 * Co-Simulation and Model Exchange, no states): the steer angle that brings a preview point of
 * the tractor onto the reference path,
 *
 *     delta = K (Y_ref(t) - (Y1 + L psi1)),
 *     Y_ref(t) = Y_target s((t - t0) / T),   s(x) = (1 - cos(pi x)) / 2 on [0, 1], 0 before, 1 after,
 *
 * a lane change of Y_target [m] from t0 over T seconds (SI; +y to the right, steer and heading
 * nose-right positive, as the vehicle FMUs).  Inputs Y1 [m] and psi1 [rad] (the vehicle FMU's
 * outputs), output delta [rad] (its input).  Every parameter has a working start value.
 * The same law is lcvreport.manoeuvres.drivers.PreviewDriver.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model.h"

static const double START[N_VR] = {DRIVER_START_K, DRIVER_START_L, DRIVER_START_TARGET, DRIVER_START_T0,
                                   DRIVER_START_T, 0.0, 0.0, 0.0};
static const char *const NAMES[N_VR] = {"gain_rad_per_m", "preview_m", "target_offset_m", "start_s", "duration_s",
                                        "Y1", "psi1", "delta"};
static const double LOW[5] = {0.0, 0.0, -20.0, 0.0, 0.0}, HIGH[5] = {1.0, 200.0, 20.0, 1e6, 100.0};
static const int LOW_OPEN[5] = {1, 0, 0, 0, 1};

const char *model_variable_name(unsigned vr) { return vr < N_VR ? NAMES[vr] : "?"; }

static double reference(const ModelState *s, double t)
{
    double x = (t - s->v[VR_T0]) / s->v[VR_T];
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return s->v[VR_TARGET];
    return s->v[VR_TARGET] * 0.5 * (1.0 - cos(M_PI * x));
}

static double steer(const ModelState *s)
{
    return s->v[VR_K] * (reference(s, s->time) - (s->v[VR_Y1] + s->v[VR_L] * s->v[VR_PSI1]));
}

void model_reset(ModelInstance *c)
{
    memset(&c->s, 0, sizeof c->s);
    c->s.phase = PhaseInstantiated;
    memcpy(c->s.v, START, sizeof c->s.v);
}

int model_exit_initialization(ModelInstance *c)
{
    for (int k = 0; k < 5; ++k) {
        double x = c->s.v[k];
        if (!isfinite(x) || x < LOW[k] || x > HIGH[k] || (LOW_OPEN[k] && x == LOW[k])) {
            snprintf(c->msg, sizeof c->msg, "%s must be in %s%g, %g], got %g", NAMES[k], LOW_OPEN[k] ? "(" : "[",
                     LOW[k], HIGH[k], x);
            return -1;
        }
    }
    return 0;
}

int model_do_step(ModelInstance *c, double h)
{
    if (!(isfinite(h) && h > 0.0)) {
        snprintf(c->msg, sizeof c->msg, "communication step size must be > 0, got %g", h);
        return -1;
    }
    c->s.time += h;
    return 0;
}

int model_get_real(ModelInstance *c, const unsigned vr[], size_t nvr, double value[])
{
    for (size_t i = 0; i < nvr; ++i) {
        if (vr[i] >= N_VR) {
            snprintf(c->msg, sizeof c->msg, "%u is not the value reference of a Real variable", vr[i]);
            return -1;
        }
        value[i] = vr[i] == VR_DELTA ? steer(&c->s) : c->s.v[vr[i]];
        if (!isfinite(value[i])) {
            snprintf(c->msg, sizeof c->msg, "%s is not finite", NAMES[vr[i]]);
            return -1;
        }
    }
    return 0;
}

int model_set_real(ModelInstance *c, unsigned vr, double value)
{
    if (vr >= N_VR || vr == VR_DELTA) {
        snprintf(c->msg, sizeof c->msg, "%u is not the value reference of a parameter or an input", vr);
        return -1;
    }
    if (vr < VR_Y1 && !(c->s.phase & (PhaseInstantiated | PhaseInitializationMode))) {
        snprintf(c->msg, sizeof c->msg, "%s is a fixed parameter: set it before initialization ends", NAMES[vr]);
        return -1;
    }
    if (!isfinite(value)) {
        snprintf(c->msg, sizeof c->msg, "%s is not finite (%g)", NAMES[vr], value);
        return -1;
    }
    c->s.v[vr] = value;
    return 0;
}

static int only_real(ModelInstance *c, unsigned vr)
{
    snprintf(c->msg, sizeof c->msg, "%u: this FMU has only Real variables", vr);
    return -1;
}

int model_get_string(ModelInstance *c, unsigned vr, const char **value) { *value = ""; return only_real(c, vr); }
int model_set_string(ModelInstance *c, unsigned vr, const char *value) { (void)value; return only_real(c, vr); }
int model_get_integer(ModelInstance *c, unsigned vr, int *value) { *value = 0; return only_real(c, vr); }
int model_set_integer(ModelInstance *c, unsigned vr, long long value) { (void)value; return only_real(c, vr); }

/* Model Exchange: no states; the reference is smooth, so no events either */
void model_get_states(ModelInstance *c, double x[], size_t nx) { (void)c; (void)x; (void)nx; }
void model_get_nominals(ModelInstance *c, double x[], size_t nx) { (void)c; (void)x; (void)nx; }
void model_set_states(ModelInstance *c, const double x[], size_t nx) { (void)c; (void)x; (void)nx; }
int model_derivatives(ModelInstance *c, double dx[], size_t nx) { (void)c; (void)dx; (void)nx; return 0; }

int model_directional(ModelInstance *c, const unsigned unknowns[], size_t nu, const unsigned knowns[], size_t nk,
                      const double seed[], double out[])
{
    (void)unknowns; (void)nu; (void)knowns; (void)nk; (void)seed; (void)out;
    snprintf(c->msg, sizeof c->msg, "directional derivatives are not provided");
    return -1;
}

int model_check_state(ModelInstance *c, const ModelState *s)
{
    for (int k = 0; k < N_VR; ++k)
        if (!isfinite(s->v[k])) {
            snprintf(c->msg, sizeof c->msg, "the FMU state is refused: %s is not finite", NAMES[k]);
            return -1;
        }
    if (memchr(s->error, '\0', sizeof s->error) == NULL || !isfinite(s->time)) {
        snprintf(c->msg, sizeof c->msg, "the FMU state is refused: it is not one this FMU wrote");
        return -1;
    }
    return 0;
}

void model_state_restored(ModelInstance *c, const ModelState *before) { (void)c; (void)before; }
