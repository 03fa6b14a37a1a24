/*
 * A path-following driver as an FMI 2.0 FMU (Co-Simulation and Model Exchange, no states):
 * the steer angle that brings a preview point of the tractor onto the reference path,
 *
 *     delta = K (Y_ref(t) - (Y1 + L psi1)),
 *     Y_ref(t) = Y_target s((t - t0) / T),   s(x) = (1 - cos(pi x)) / 2 on [0, 1], 0 before, 1 after,
 *
 * a lane change of Y_target [m] from t0 over T seconds (SI; +y to the right, steer and heading
 * nose-right positive, as the vehicle FMUs).  Inputs Y1 [m] and psi1 [rad] (the vehicle FMU's
 * outputs), output delta [rad] (its input).  Every parameter has a working start value.
 * The same law is lcvreport.analysis.driver.PreviewDriver.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_common.h"
#include "driver_config.h"

enum { VR_K, VR_L, VR_TARGET, VR_T0, VR_T, VR_Y1, VR_PSI1, VR_DELTA, N_VR };
static const double START[N_VR] = {DRIVER_START_K, DRIVER_START_L, DRIVER_START_TARGET, DRIVER_START_T0,
                                   DRIVER_START_T, 0.0, 0.0, 0.0};
static const char *const NAMES[N_VR] = {"gain_rad_per_m", "preview_m", "target_offset_m", "start_s", "duration_s",
                                        "Y1", "psi1", "delta"};
static const double LOW[5] = {0.0, 0.0, -20.0, 0.0, 0.0}, HIGH[5] = {1.0, 200.0, 20.0, 1e6, 100.0};
static const int LOW_OPEN[5] = {1, 0, 0, 0, 1};

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    int logging_on, model_exchange, phase;
    double v[N_VR];
    double time;
} Driver;

static void logmsg(Driver *d, fmi2Status status, const char *fmt, ...)
{
    char esc[1200];
    va_list ap;
    if (!d || !d->cb.logger) return;
    if (!d->logging_on && status < fmi2Warning) return;
    va_start(ap, fmt);
    format_log_message(esc, sizeof esc, fmt, ap);
    va_end(ap);
    d->cb.logger(d->cb.componentEnvironment, d->name, status, log_category(status), esc);
}

static int allowed(Driver *d, const char *f, int mask)
{
    if (!d) return 0;
    if (!(d->phase & mask)) {
        logmsg(d, fmi2Error, "%s must not be called in phase %s", f, phase_name(d->phase));
        return 0;
    }
    return 1;
}

#define RUNNING (PhaseStepComplete | PhaseEventMode | PhaseContinuousTimeMode)
#define BEGIN(F, MASK) Driver *d = (Driver *)c; if (!allowed(d, #F, (MASK))) return fmi2Error;

static double reference(const Driver *d, double t)
{
    double x = (t - d->v[VR_T0]) / d->v[VR_T];
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return d->v[VR_TARGET];
    return d->v[VR_TARGET] * 0.5 * (1.0 - cos(M_PI * x));
}

static double steer(const Driver *d)
{
    return d->v[VR_K] * (reference(d, d->time) - (d->v[VR_Y1] + d->v[VR_L] * d->v[VR_PSI1]));
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[])
{
    Driver *d = (Driver *)c;
    if (!d) return fmi2Error;
    if (n > 0 && !cats) { logmsg(d, fmi2Error, "fmi2SetDebugLogging: null array"); return fmi2Error; }
    d->logging_on = on ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)location; (void)visible;
    if (!functions || !functions->logger) return NULL;
    const char *name = instanceName ? instanceName : "driver";
    if (!guid || strcmp(guid, DRIVER_GUID) != 0) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "guid mismatch: the modelDescription.xml does not belong to this binary");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError", "unknown fmuType");
        return NULL;
    }
    Driver *d = (Driver *)calloc(1, sizeof(Driver));
    if (!d || !(d->name = (char *)malloc(strlen(name) + 1))) {
        free(d);
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError", "out of memory");
        return NULL;
    }
    strcpy(d->name, name);
    memcpy((void *)&d->cb, functions, sizeof d->cb);
    d->logging_on = loggingOn ? 1 : 0;
    d->model_exchange = fmuType == fmi2ModelExchange;
    d->phase = PhaseInstantiated;
    memcpy(d->v, START, sizeof d->v);
    return d;
}

void fmi2FreeInstance(fmi2Component c)
{
    Driver *d = (Driver *)c;
    if (!d) return;
    free(d->name);
    free(d);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real start, fmi2Boolean stopDef,
                               fmi2Real stop)
{
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    BEGIN(fmi2SetupExperiment, PhaseInstantiated)
    if (!isfinite(start)) { logmsg(d, fmi2Error, "startTime is not finite"); return fmi2Error; }
    d->time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    BEGIN(fmi2EnterInitializationMode, PhaseInstantiated)
    d->phase = PhaseInitializationMode;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    BEGIN(fmi2ExitInitializationMode, PhaseInitializationMode)
    for (int k = 0; k < 5; ++k) {
        double x = d->v[k];
        if (!isfinite(x) || x < LOW[k] || x > HIGH[k] || (LOW_OPEN[k] && x == LOW[k])) {
            logmsg(d, fmi2Error, "%s must be in %s%g, %g], got %g", NAMES[k], LOW_OPEN[k] ? "(" : "[", LOW[k], HIGH[k], x);
            d->phase = PhaseError;
            return fmi2Error;
        }
    }
    d->phase = d->model_exchange ? PhaseEventMode : PhaseStepComplete;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    BEGIN(fmi2Terminate, RUNNING | PhaseError)
    d->phase = PhaseTerminated;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    Driver *d = (Driver *)c;
    if (!d) return fmi2Error;
    d->phase = PhaseInstantiated;
    d->time = 0.0;
    memcpy(d->v, START, sizeof d->v);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    BEGIN(fmi2GetReal, ANY_PHASE)
    if (n == 0) return fmi2OK;
    if (!vr || !value) { logmsg(d, fmi2Error, "fmi2GetReal: null array"); return fmi2Error; }
    for (size_t i = 0; i < n; ++i) {
        if (vr[i] >= N_VR) { logmsg(d, fmi2Error, "fmi2GetReal: no variable %u", vr[i]); return fmi2Error; }
        value[i] = vr[i] == VR_DELTA ? steer(d) : d->v[vr[i]];
        if (!isfinite(value[i])) { logmsg(d, fmi2Error, "%s is not finite", NAMES[vr[i]]); return fmi2Error; }
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[])
{
    BEGIN(fmi2SetReal, PhaseInstantiated | PhaseInitializationMode | RUNNING)
    if (n == 0) return fmi2OK;
    if (!vr || !value) { logmsg(d, fmi2Error, "fmi2SetReal: null array"); return fmi2Error; }
    for (size_t i = 0; i < n; ++i) {
        unsigned r = vr[i];
        if (r >= N_VR || r == VR_DELTA) { logmsg(d, fmi2Error, "fmi2SetReal: %u is not a parameter or input", r); return fmi2Error; }
        if (r < VR_Y1 && !(d->phase & (PhaseInstantiated | PhaseInitializationMode))) {
            logmsg(d, fmi2Error, "%s is a fixed parameter: set it before initialization ends", NAMES[r]);
            return fmi2Error;
        }
        if (!isfinite(value[i])) { logmsg(d, fmi2Error, "%s is not finite (%g)", NAMES[r], value[i]); return fmi2Error; }
        d->v[r] = value[i];
    }
    return fmi2OK;
}

static fmi2Status none(fmi2Component c, size_t n, const char *f)
{
    Driver *d = (Driver *)c;
    if (!d) return fmi2Error;
    if (n == 0) return fmi2OK;
    logmsg(d, fmi2Error, "%s: this FMU has only Real variables", f);
    return fmi2Error;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
{ (void)vr; (void)v; return none(c, n, "fmi2GetInteger"); }
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
{ (void)vr; (void)v; return none(c, n, "fmi2SetInteger"); }
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
{ (void)vr; (void)v; return none(c, n, "fmi2GetBoolean"); }
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
{ (void)vr; (void)v; return none(c, n, "fmi2SetBoolean"); }
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
{ (void)vr; (void)v; return none(c, n, "fmi2GetString"); }
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
{ (void)vr; (void)v; return none(c, n, "fmi2SetString"); }

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSet)
{
    (void)t; (void)noSet;
    BEGIN(fmi2DoStep, PhaseStepComplete)
    if (!(isfinite(h) && h > 0.0)) { logmsg(d, fmi2Error, "communication step size must be > 0, got %g", h); return fmi2Error; }
    d->time += h;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    Driver *d = (Driver *)c;
    if (d) logmsg(d, fmi2Error, "fmi2CancelStep: steps are not asynchronous");
    return fmi2Error;
}

/* Model Exchange: no states, no events but the time of the reference (smooth) */
fmi2Status fmi2SetTime(fmi2Component c, fmi2Real t)
{
    BEGIN(fmi2SetTime, PhaseEventMode | PhaseContinuousTimeMode)
    if (!isfinite(t)) { logmsg(d, fmi2Error, "fmi2SetTime: time is not finite"); return fmi2Error; }
    d->time = t;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    (void)x;
    BEGIN(fmi2SetContinuousStates, PhaseEventMode | PhaseContinuousTimeMode)
    if (nx != 0) { logmsg(d, fmi2Error, "fmi2SetContinuousStates: this FMU has no states"); return fmi2Error; }
    return fmi2OK;
}

#define NO_STATES(F, T) \
fmi2Status F(fmi2Component c, T x[], size_t nx) \
{ (void)x; BEGIN(F, ANY_PHASE) \
  if (nx != 0) { logmsg(d, fmi2Error, #F ": this FMU has no states or event indicators"); return fmi2Error; } \
  return fmi2OK; }
NO_STATES(fmi2GetDerivatives, fmi2Real)
NO_STATES(fmi2GetEventIndicators, fmi2Real)
NO_STATES(fmi2GetContinuousStates, fmi2Real)
NO_STATES(fmi2GetNominalsOfContinuousStates, fmi2Real)

fmi2Status fmi2EnterEventMode(fmi2Component c)
{
    BEGIN(fmi2EnterEventMode, PhaseEventMode | PhaseContinuousTimeMode)
    d->phase = PhaseEventMode;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info)
{
    BEGIN(fmi2NewDiscreteStates, PhaseEventMode)
    if (!info) { logmsg(d, fmi2Error, "fmi2NewDiscreteStates: null pointer"); return fmi2Error; }
    memset(info, 0, sizeof *info);
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
{
    BEGIN(fmi2EnterContinuousTimeMode, PhaseEventMode)
    d->phase = PhaseContinuousTimeMode;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSet, fmi2Boolean *enter, fmi2Boolean *term)
{
    (void)noSet;
    BEGIN(fmi2CompletedIntegratorStep, PhaseContinuousTimeMode)
    if (!enter || !term) { logmsg(d, fmi2Error, "fmi2CompletedIntegratorStep: null pointer"); return fmi2Error; }
    *enter = fmi2False;
    *term = fmi2False;
    return fmi2OK;
}

/* not provided */
static fmi2Status refuse(fmi2Component c, const char *what)
{
    Driver *d = (Driver *)c;
    if (d) logmsg(d, fmi2Error, "%s", what);
    return fmi2Error;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return refuse(c, "FMU states are not supported"); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)s; return refuse(c, "FMU states are not supported"); }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return refuse(c, "FMU states are not supported"); }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n)
{ (void)s; (void)n; return refuse(c, "FMU states are not supported"); }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n)
{ (void)s; (void)b; (void)n; return refuse(c, "FMU states are not supported"); }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s)
{ (void)s; (void)b; (void)n; return refuse(c, "FMU states are not supported"); }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference k[], size_t nk, const fmi2Real dk[], fmi2Real du[])
{ (void)u; (void)nu; (void)k; (void)nk; (void)dk; (void)du; return refuse(c, "directional derivatives are not provided"); }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real v[])
{ (void)vr; (void)n; (void)order; (void)v; return refuse(c, "input derivatives are not supported"); }
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real v[])
{ (void)vr; (void)n; (void)order; (void)v; return refuse(c, "output derivatives are not provided"); }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v)
{ (void)s; if (!c || !v) return fmi2Error; *v = fmi2OK; return fmi2OK; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v)
{
    Driver *d = (Driver *)c;
    if (!d || !v) return fmi2Error;
    if (s == fmi2LastSuccessfulTime) { *v = d->time; return fmi2OK; }
    return fmi2Discard;
}
