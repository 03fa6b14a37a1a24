/*
 * The FMI 2.0 co-simulation API of the native FMU and its state machine, once for
 * every vehicle (cf. Reference-FMUs src/fmi2Functions.c): each call checks the
 * instance, its arguments and the phase it is allowed in (MASK_*), then calls the
 * model (model.c).  No call sequence or argument returns fmi2Fatal, loops forever or
 * touches memory it does not own; a refused call returns fmi2Error with a log message
 * that names what was wrong.
 *
 * Built with the official FMI 2.0 headers (fmi2Functions.h, shipped by fmpy) and the
 * generated config.h / vehicle_data.h.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_common.h"
#include "model.h"

/* an FMI 2 instance: the model's, and what is FMI's (the host's callbacks) */
typedef struct {
    ModelInstance m;                      /* first: an Instance2* is a ModelInstance* */
    fmi2CallbackFunctions cb;
} Instance2;

/* phases a call is allowed in (Model Exchange: EventMode and ContinuousTimeMode after
   initialization instead of StepComplete) */
#define RUNNING (PhaseStepComplete | PhaseEventMode | PhaseContinuousTimeMode)
#define MASK_fmi2SetupExperiment PhaseInstantiated
#define MASK_fmi2EnterInitializationMode PhaseInstantiated
#define MASK_fmi2ExitInitializationMode PhaseInitializationMode
#define MASK_fmi2Terminate (RUNNING | PhaseError)
#define MASK_fmi2DoStep PhaseStepComplete
#define MASK_fmi2GetReal ANY_PHASE
#define MASK_fmi2SetReal (PhaseInstantiated | PhaseInitializationMode | RUNNING)
#define MASK_fmi2SetTime (PhaseEventMode | PhaseContinuousTimeMode)
#define MASK_fmi2SetContinuousStates (PhaseEventMode | PhaseContinuousTimeMode)
#define MASK_fmi2GetDerivatives (PhaseInitializationMode | PhaseEventMode | PhaseContinuousTimeMode | \
                                 PhaseTerminated | PhaseError)
#define MASK_fmi2GetEventIndicators MASK_fmi2GetDerivatives
#define MASK_fmi2GetContinuousStates MASK_fmi2GetDerivatives
#define MASK_fmi2GetNominalsOfContinuousStates (PhaseInstantiated | MASK_fmi2GetDerivatives)
#define MASK_fmi2EnterEventMode (PhaseEventMode | PhaseContinuousTimeMode)
#define MASK_fmi2NewDiscreteStates PhaseEventMode
#define MASK_fmi2EnterContinuousTimeMode PhaseEventMode
#define MASK_fmi2CompletedIntegratorStep PhaseContinuousTimeMode
#define MASK_fmi2SetString (PhaseInstantiated | PhaseInitializationMode)
#define MASK_fmi2GetString ANY_PHASE
#define MASK_fmi2SetInteger (PhaseInstantiated | PhaseInitializationMode)
#define MASK_fmi2GetInteger ANY_PHASE

static void logmsg(Instance2 *c, fmi2Status status, const char *fmt, ...)
{
    char esc[2400];
    va_list ap;
    if (!c || !c->cb.logger) return;
    if (!c->m.logging_on && status < fmi2Warning) return;
    va_start(ap, fmt);
    format_log_message(esc, sizeof esc, 1, fmt, ap);
    va_end(ap);
    c->cb.logger(c->cb.componentEnvironment, c->m.name, status, log_category(status), esc);
}

/* check the instance and the phase; on failure log and return fmi2Error */
static int allowed(Instance2 *c, const char *function, int mask)
{
    if (!c) return 0;
    if (!(c->m.s.phase & mask)) {
        logmsg(c, fmi2Error, "%s must not be called in phase %s", function, phase_name(c->m.s.phase));
        return 0;
    }
    return 1;
}

#define BEGIN_FUNCTION(F) \
    Instance2 *c = (Instance2 *)comp; \
    if (!allowed(c, "fmi2" #F, MASK_fmi2##F)) return fmi2Error;

/* ------------------------------------------------------------------ inquiry and set-up */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    (void)categories;
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (nCategories > 0 && !categories) {
        logmsg(c, fmi2Error, "fmi2SetDebugLogging: %u categories but no array", (unsigned)nCategories);
        return fmi2Error;
    }
    c->m.logging_on = loggingOn;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)fmuResourceLocation; (void)visible;
    if (!functions || !functions->logger) return NULL;
    const char *name = instanceName ? instanceName : LCV_MODEL_IDENTIFIER_TEXT;
    if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmuType must be fmi2ModelExchange or fmi2CoSimulation");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, LCV_GUID) != 0) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "guid mismatch: the modelDescription.xml does not belong to this binary");
        return NULL;
    }
    Instance2 *c = (Instance2 *)calloc(1, sizeof(Instance2));
    if (!c) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError", "out of memory");
        return NULL;
    }
    memcpy((void *)&c->cb, functions, sizeof(fmi2CallbackFunctions));
    c->m.name = (char *)malloc(strlen(name) + 1);
    if (!c->m.name) { free(c); return NULL; }
    strcpy(c->m.name, name);
    c->m.logging_on = loggingOn;
    c->m.model_exchange = fmuType == fmi2ModelExchange;
    model_reset(&c->m);
    return c;
}

void fmi2FreeInstance(fmi2Component comp)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return;
    free(c->m.name);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    BEGIN_FUNCTION(SetupExperiment)
    if (!isfinite(startTime)) {
        logmsg(c, fmi2Error, "fmi2SetupExperiment: startTime is not finite (%g)", startTime);
        return fmi2Error;
    }
    c->m.s.time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp)
{
    BEGIN_FUNCTION(EnterInitializationMode)
    c->m.s.phase = PhaseInitializationMode;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp)
{
    BEGIN_FUNCTION(ExitInitializationMode)
    double t0 = c->m.s.time;
    if (model_exit_initialization(&c->m) != 0) {
        snprintf(c->m.s.error, sizeof c->m.s.error, "%s", c->m.msg);
        c->m.s.phase = PhaseError;
        logmsg(c, fmi2Error, "%s; every doStep will be refused (fmi2Reset to start again)", c->m.s.error);
        return fmi2Error;
    }
    c->m.s.time = t0;
    c->m.s.phase = c->m.model_exchange ? PhaseEventMode : PhaseStepComplete;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp)
{
    BEGIN_FUNCTION(Terminate)
    c->m.s.phase = PhaseTerminated;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component comp)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    model_reset(&c->m);
    return fmi2OK;
}

/* ------------------------------------------------------------------ values */
fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    BEGIN_FUNCTION(GetReal)
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) { logmsg(c, fmi2Error, "fmi2GetReal: null array"); return fmi2Error; }
    if (model_get_real(&c->m, vr, nvr, value) != 0) {
        logmsg(c, fmi2Error, "fmi2GetReal: %s", c->m.msg);
        return fmi2Error;
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    BEGIN_FUNCTION(SetReal)
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) { logmsg(c, fmi2Error, "fmi2SetReal: null array"); return fmi2Error; }
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < nvr; ++i) {
        if (model_set_real(&c->m, vr[i], value[i]) != 0) {
            logmsg(c, fmi2Error, "fmi2SetReal: %s", c->m.msg);
            status = fmi2Error;
        }
    }
    return status;
}

fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    BEGIN_FUNCTION(GetString)
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) { logmsg(c, fmi2Error, "fmi2GetString: null array"); return fmi2Error; }
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < nvr; ++i) {
        if (model_get_string(&c->m, vr[i], &value[i]) != 0) {
            logmsg(c, fmi2Error, "fmi2GetString: %s", c->m.msg);
            status = fmi2Error;
        }
    }
    return status;
}

fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    BEGIN_FUNCTION(SetString)
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) { logmsg(c, fmi2Error, "fmi2SetString: null array"); return fmi2Error; }
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < nvr; ++i) {
        if (model_set_string(&c->m, vr[i], value[i]) != 0) {
            logmsg(c, fmi2Error, "fmi2SetString: %s", c->m.msg);
            status = fmi2Error;
        }
    }
    return status;
}

static fmi2Status no_variables(fmi2Component comp, size_t nvr, const char *function, const char *type)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    logmsg(c, fmi2Error, "%s: this FMU has no %s variables", function, type);
    return fmi2Error;
}

/* Integer access: the Enumeration preset (SPEC section 15) */
fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    BEGIN_FUNCTION(GetInteger)
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) { logmsg(c, fmi2Error, "fmi2GetInteger: null array"); return fmi2Error; }
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < nvr; ++i) {
        int v = 0;
        if (model_get_integer(&c->m, vr[i], &v) != 0) {
            logmsg(c, fmi2Error, "fmi2GetInteger: %s", c->m.msg);
            status = fmi2Error;
        }
        value[i] = v;
    }
    return status;
}

fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    BEGIN_FUNCTION(SetInteger)
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) { logmsg(c, fmi2Error, "fmi2SetInteger: null array"); return fmi2Error; }
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < nvr; ++i) {
        if (model_set_integer(&c->m, vr[i], value[i]) != 0) {
            logmsg(c, fmi2Error, "fmi2SetInteger: %s", c->m.msg);
            status = fmi2Error;
        }
    }
    return status;
}

fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    (void)vr; (void)value;
    return no_variables(comp, nvr, "fmi2GetBoolean", "Boolean");
}

fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    (void)vr; (void)value;
    return no_variables(comp, nvr, "fmi2SetBoolean", "Boolean");
}

/* ------------------------------------------------------------------ stepping */
fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint)
{
    (void)currentCommunicationPoint; (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (c->m.s.phase == PhaseError) {
        logmsg(c, fmi2Error, "%s; every doStep will be refused (fmi2Reset to start again)", c->m.s.error);
        return fmi2Error;
    }
    if (!allowed(c, "fmi2DoStep", MASK_fmi2DoStep)) return fmi2Error;
    if (!isfinite(currentCommunicationPoint)) {
        logmsg(c, fmi2Error, "fmi2DoStep: currentCommunicationPoint is not finite (%g)", currentCommunicationPoint);
        return fmi2Error;
    }
    int r = model_do_step(&c->m, communicationStepSize);
    if (r < 0) {
        logmsg(c, fmi2Error, "%s", c->m.msg);
        return fmi2Error;
    }
    if (r > 0) logmsg(c, fmi2Warning, "%s", c->m.msg);
    return r > 0 ? fmi2Warning : fmi2OK;    /* a clamped speed: the Python FMU's status too */
}

fmi2Status fmi2CancelStep(fmi2Component comp)
{
    Instance2 *c = (Instance2 *)comp;
    if (c) logmsg(c, fmi2Error, "fmi2CancelStep: steps are not asynchronous");
    return fmi2Error;
}

/* ------------------------------------------------------------------ Model Exchange */
fmi2Status fmi2SetTime(fmi2Component comp, fmi2Real time)
{
    BEGIN_FUNCTION(SetTime)
    if (!isfinite(time)) { logmsg(c, fmi2Error, "fmi2SetTime: time is not finite (%g)", time); return fmi2Error; }
    c->m.s.time = time;
    return fmi2OK;
}

static int states_arg(Instance2 *c, const char *function, const void *x, size_t nx)
{
    if (nx != LCV_N_ME_STATES) {
        logmsg(c, fmi2Error, "%s: %u states given, this FMU has %u", function, (unsigned)nx, (unsigned)LCV_N_ME_STATES);
        return 0;
    }
    if (nx > 0 && !x) { logmsg(c, fmi2Error, "%s: null array", function); return 0; }
    return 1;
}

fmi2Status fmi2SetContinuousStates(fmi2Component comp, const fmi2Real x[], size_t nx)
{
    BEGIN_FUNCTION(SetContinuousStates)
    if (!states_arg(c, "fmi2SetContinuousStates", x, nx)) return fmi2Error;
    for (size_t i = 0; i < nx; ++i)
        if (!isfinite(x[i])) {
            logmsg(c, fmi2Error, "fmi2SetContinuousStates: state %s is not finite (%g); the states are unchanged",
                   LCV_VARIABLE_NAME(LCV_ME_STATE_VR_OF(i)), x[i]);
            return fmi2Error;
        }
    model_set_states(&c->m, x, nx);
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component comp, fmi2Real x[], size_t nx)
{
    BEGIN_FUNCTION(GetContinuousStates)
    if (!states_arg(c, "fmi2GetContinuousStates", x, nx)) return fmi2Error;
    model_get_states(&c->m, x, nx);
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component comp, fmi2Real dx[], size_t nx)
{
    BEGIN_FUNCTION(GetDerivatives)
    if (!states_arg(c, "fmi2GetDerivatives", dx, nx)) return fmi2Error;
    int r = model_derivatives(&c->m, dx, nx);
    if (r < 0) { logmsg(c, fmi2Error, "%s", c->m.msg); return fmi2Error; }
    if (r > 0) logmsg(c, fmi2Warning, "%s", c->m.msg);
    return r > 0 ? fmi2Warning : fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component comp, fmi2Real x_nominal[], size_t nx)
{
    BEGIN_FUNCTION(GetNominalsOfContinuousStates)
    if (!states_arg(c, "fmi2GetNominalsOfContinuousStates", x_nominal, nx)) return fmi2Error;
    model_get_nominals(&c->m, x_nominal, nx);     /* each state's physical scale */
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component comp, fmi2Real eventIndicators[], size_t ni)
{
    BEGIN_FUNCTION(GetEventIndicators)
    (void)eventIndicators;
    if (ni != 0) { logmsg(c, fmi2Error, "fmi2GetEventIndicators: this FMU has no event indicators"); return fmi2Error; }
    return fmi2OK;
}

fmi2Status fmi2EnterEventMode(fmi2Component comp)
{
    BEGIN_FUNCTION(EnterEventMode)
    c->m.s.phase = PhaseEventMode;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component comp, fmi2EventInfo *eventInfo)
{
    BEGIN_FUNCTION(NewDiscreteStates)
    if (!eventInfo) { logmsg(c, fmi2Error, "fmi2NewDiscreteStates: null pointer"); return fmi2Error; }
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    eventInfo->nextEventTimeDefined = fmi2False;
    eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component comp)
{
    BEGIN_FUNCTION(EnterContinuousTimeMode)
    c->m.s.phase = PhaseContinuousTimeMode;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component comp, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN_FUNCTION(CompletedIntegratorStep)
    if (!enterEventMode || !terminateSimulation) {
        logmsg(c, fmi2Error, "fmi2CompletedIntegratorStep: null pointer");
        return fmi2Error;
    }
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

/* ------------------------------------------------------------------ FMU state */
#define STATE_MAGIC 0x4C43564EU          /* "LCVN" */
typedef struct {
    unsigned magic;
    unsigned size;
    char guid[64];
    ModelState s;
} Snapshot;

static int snapshot_ok(Instance2 *c, const Snapshot *snap)
{
    if (snap->magic != STATE_MAGIC || snap->size != sizeof(Snapshot) ||
        memchr(snap->guid, '\0', sizeof snap->guid) == NULL || strcmp(snap->guid, LCV_GUID) != 0) {
        logmsg(c, fmi2Error, "the FMU state was not written by this FMU (another model or version)");
        return 0;
    }
    if (model_check_state(&c->m, &snap->s) != 0) {
        logmsg(c, fmi2Error, "%s", c->m.msg);
        return 0;
    }
    return 1;
}

fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (!state) { logmsg(c, fmi2Error, "fmi2GetFMUstate: null pointer"); return fmi2Error; }
    Snapshot *snap = (Snapshot *)(*state);
    if (!snap) {
        snap = (Snapshot *)calloc(1, sizeof(Snapshot));
        if (!snap) { logmsg(c, fmi2Error, "fmi2GetFMUstate: out of memory"); return fmi2Error; }
    }
    snap->magic = STATE_MAGIC;
    snap->size = (unsigned)sizeof(Snapshot);
    memset(snap->guid, 0, sizeof snap->guid);
    snprintf(snap->guid, sizeof snap->guid, "%s", LCV_GUID);
    snap->s = c->m.s;
    *state = snap;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    const Snapshot *snap = (const Snapshot *)state;
    if (!snap) { logmsg(c, fmi2Error, "fmi2SetFMUstate: null state"); return fmi2Error; }
    if (!snapshot_ok(c, snap)) return fmi2Error;
    ModelState before = c->m.s;
    c->m.s = snap->s;
    model_state_restored(&c->m, &before);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    if (!comp) return fmi2Error;
    if (!state) { logmsg((Instance2 *)comp, fmi2Error, "fmi2FreeFMUstate: null pointer"); return fmi2Error; }
    free(*state);
    *state = NULL;
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (!state || !size) { logmsg(c, fmi2Error, "fmi2SerializedFMUstateSize: null pointer"); return fmi2Error; }
    *size = sizeof(Snapshot);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte serializedState[], size_t size)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (!state || !serializedState) { logmsg(c, fmi2Error, "fmi2SerializeFMUstate: null pointer"); return fmi2Error; }
    if (size < sizeof(Snapshot)) {
        logmsg(c, fmi2Error, "fmi2SerializeFMUstate: %u bytes given, %u needed", (unsigned)size,
               (unsigned)sizeof(Snapshot));
        return fmi2Error;
    }
    memcpy(serializedState, state, sizeof(Snapshot));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *state)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c) return fmi2Error;
    if (!serializedState || !state) { logmsg(c, fmi2Error, "fmi2DeSerializeFMUstate: null pointer"); return fmi2Error; }
    if (size != sizeof(Snapshot)) {
        logmsg(c, fmi2Error, "serialized FMU state of %u bytes: expected %u", (unsigned)size, (unsigned)sizeof(Snapshot));
        return fmi2Error;
    }
    Snapshot tmp;
    memcpy(&tmp, serializedState, sizeof tmp);
    if (!snapshot_ok(c, &tmp)) return fmi2Error;
    Snapshot *snap = (Snapshot *)(*state);
    if (!snap) {
        snap = (Snapshot *)malloc(sizeof(Snapshot));
        if (!snap) { logmsg(c, fmi2Error, "fmi2DeSerializeFMUstate: out of memory"); return fmi2Error; }
    }
    *snap = tmp;
    *state = snap;
    return fmi2OK;
}

/* ------------------------------------------------------------------ not provided */
#define MASK_fmi2GetDirectionalDerivative (PhaseInitializationMode | RUNNING | PhaseTerminated | PhaseError)
fmi2Status fmi2GetDirectionalDerivative(fmi2Component comp, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    BEGIN_FUNCTION(GetDirectionalDerivative)
    if (nUnknown == 0) return fmi2OK;
    if (!vUnknown_ref || !dvUnknown || (nKnown > 0 && (!vKnown_ref || !dvKnown))) {
        logmsg(c, fmi2Error, "fmi2GetDirectionalDerivative: null array");
        return fmi2Error;
    }
    if (model_directional(&c->m, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown) != 0) {
        logmsg(c, fmi2Error, "%s", c->m.msg);
        return fmi2Error;
    }
    return fmi2OK;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    if (comp) logmsg((Instance2 *)comp, fmi2Error, "input derivatives are not supported");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    if (comp) logmsg((Instance2 *)comp, fmi2Error, "output derivatives are not provided");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    if (!comp || !value) return fmi2Error;
    *value = fmi2OK;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value)
{
    Instance2 *c = (Instance2 *)comp;
    if (!c || !value) return fmi2Error;
    if (s == fmi2LastSuccessfulTime) { *value = c->m.s.time; return fmi2OK; }
    return fmi2Discard;
}

