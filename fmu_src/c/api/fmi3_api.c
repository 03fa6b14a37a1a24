/*
 * The FMI 3.0 API of the native FMU (Co-Simulation and Model Exchange) over the same model
 * as the FMI 2.0 one (model.c), cf. Reference-FMUs src/fmi3Functions.c: each call checks
 * the instance, its arguments and the phase it is allowed in, then calls the model.  No
 * call sequence or argument returns fmi3Fatal, loops or touches memory it does not own; a
 * refused call returns fmi3Error with a log message naming what was wrong, whatever the
 * logging flag.  Scheduled Execution, clocks and the types this FMU has no variables of
 * answer fmi3Error.
 *
 * Built with -DLCV_FMI3 and the official FMI 3.0 headers (fmi3Functions.h, shipped by
 * fmpy); the value reference of the independent variable "time" follows the derivatives.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "model.h"

#define LCV_TIME_VR (LCV_FIRST_DERIVATIVE + LCV_N_ME_STATES)
#define RUNNING (PhaseStepComplete | PhaseEventMode | PhaseContinuousTimeMode)

typedef struct {
    ModelInstance m;                      /* first: a ModelInstance* is an Instance3* */
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Instance3;

static void logmsg(Instance3 *c, fmi3Status status, const char *fmt, ...)
{
    char esc[2400];
    va_list ap;
    if (!c || !c->log) return;
    if (!c->m.logging_on && status < fmi3Warning) return;
    va_start(ap, fmt);
    format_log_message(esc, sizeof esc, 0, fmt, ap);
    va_end(ap);
    c->log(c->env, status, log_category(status), esc);
}

static int allowed(Instance3 *c, const char *function, int mask)
{
    if (!c) return 0;
    if (!(c->m.s.phase & mask)) {
        logmsg(c, fmi3Error, "%s must not be called in phase %s", function, phase_name(c->m.s.phase));
        return 0;
    }
    return 1;
}

#define BEGIN(F, MASK) \
    Instance3 *c = (Instance3 *)instance; \
    if (!allowed(c, #F, (MASK))) return fmi3Error;

/* ------------------------------------------------------------------ inquiry, instances */
const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (nCategories > 0 && !categories) {
        logmsg(c, fmi3Error, "fmi3SetDebugLogging: %u categories but no array", (unsigned)nCategories);
        return fmi3Error;
    }
    c->m.logging_on = loggingOn ? 1 : 0;
    return fmi3OK;
}

static fmi3Instance instantiate(fmi3String instanceName, fmi3String token, fmi3Boolean loggingOn,
                                fmi3InstanceEnvironment env, fmi3LogMessageCallback log, int me)
{
    if (!log) return NULL;
    if (!token || strcmp(token, LCV_GUID) != 0) {
        log(env, fmi3Error, "logStatusError", "instantiation token mismatch: the modelDescription.xml does not "
            "belong to this binary");
        return NULL;
    }
    const char *name = instanceName ? instanceName : LCV_MODEL_IDENTIFIER_TEXT;
    Instance3 *c = (Instance3 *)calloc(1, sizeof(Instance3));
    if (!c) { log(env, fmi3Error, "logStatusError", "out of memory"); return NULL; }
    c->m.name = (char *)malloc(strlen(name) + 1);
    if (!c->m.name) { free(c); log(env, fmi3Error, "logStatusError", "out of memory"); return NULL; }
    strcpy(c->m.name, name);
    c->env = env;
    c->log = log;
    c->m.logging_on = loggingOn ? 1 : 0;
    c->m.model_exchange = me;
    model_reset(&c->m);
    return c;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)resourcePath; (void)visible;
    return instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 1);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    (void)resourcePath; (void)visible; (void)eventModeUsed; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
    return instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 0);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                               LCV_MODEL_IDENTIFIER_TEXT " offers Co-Simulation and Model Exchange, not Scheduled Execution");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return;
    free(c->m.name);
    free(c);
}

/* ------------------------------------------------------------------ initialization, end */
fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    BEGIN(fmi3EnterInitializationMode, PhaseInstantiated)
    if (!isfinite(startTime)) {
        logmsg(c, fmi3Error, "fmi3EnterInitializationMode: startTime is not finite (%g)", startTime);
        return fmi3Error;
    }
    c->m.s.time = startTime;
    c->m.s.phase = PhaseInitializationMode;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    BEGIN(fmi3ExitInitializationMode, PhaseInitializationMode)
    double t0 = c->m.s.time;
    if (model_exit_initialization(&c->m) != 0) {
        snprintf(c->m.s.error, sizeof c->m.s.error, "%s", c->m.msg);
        c->m.s.phase = PhaseError;
        logmsg(c, fmi3Error, "%s; every step will be refused (fmi3Reset to start again)", c->m.s.error);
        return fmi3Error;
    }
    c->m.s.time = t0;
    c->m.s.phase = c->m.model_exchange ? PhaseEventMode : PhaseStepComplete;
    return fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    BEGIN(fmi3EnterEventMode, PhaseContinuousTimeMode)      /* from Continuous-Time Mode (Model Exchange) only */
    c->m.s.phase = PhaseEventMode;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    BEGIN(fmi3Terminate, RUNNING | PhaseError)
    c->m.s.phase = PhaseTerminated;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    model_reset(&c->m);
    return fmi3OK;
}

/* ------------------------------------------------------------------ values */
static int scalar_args(Instance3 *c, const char *function, const void *vr, size_t nvr, const void *values,
                       size_t nValues)
{
    if (nvr == 0) return 1;
    if (!vr || !values) { logmsg(c, fmi3Error, "%s: null array", function); return 0; }
    if (nValues != nvr) {
        logmsg(c, fmi3Error, "%s: %u values for %u value references (every variable is a scalar)", function,
               (unsigned)nValues, (unsigned)nvr);
        return 0;
    }
    return 1;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues)
{
    BEGIN(fmi3GetFloat64, ANY_PHASE)
    if (!scalar_args(c, "fmi3GetFloat64", valueReferences, nValueReferences, values, nValues)) return fmi3Error;
    fmi3Status status = fmi3OK;
    /* every value but the time in one call of the model (the outputs computed once, as FMI 2's
       GetReal), in blocks of GET_BLOCK; a block the model refuses is asked again value by value,
       so that each bad value reference is logged as before */
    enum { GET_BLOCK = 512 };
    unsigned vr[GET_BLOCK];
    double got[GET_BLOCK];
    size_t at[GET_BLOCK];
    int refused = 0;
    for (size_t start = 0; start < nValueReferences && !refused; start += GET_BLOCK) {
        size_t end = start + GET_BLOCK < nValueReferences ? start + GET_BLOCK : nValueReferences, n = 0;
        for (size_t i = start; i < end; ++i) {
            if (valueReferences[i] == LCV_TIME_VR) { values[i] = c->m.s.time; continue; }
            vr[n] = valueReferences[i];
            at[n++] = i;
        }
        if (n && model_get_real(&c->m, vr, n, got) != 0) { refused = 1; break; }
        for (size_t k = 0; k < n; ++k) values[at[k]] = got[k];
    }
    if (!refused) return status;
    for (size_t i = 0; i < nValueReferences; ++i) {
        fmi3ValueReference r = valueReferences[i];
        if (r == LCV_TIME_VR) { values[i] = c->m.s.time; continue; }
        unsigned r2 = r;
        if (model_get_real(&c->m, &r2, 1, &values[i]) != 0) {
            logmsg(c, fmi3Error, "fmi3GetFloat64: %s", c->m.msg);
            status = fmi3Error;
        }
    }
    return status;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues)
{
    BEGIN(fmi3SetFloat64, PhaseInstantiated | PhaseInitializationMode | RUNNING)
    if (!scalar_args(c, "fmi3SetFloat64", valueReferences, nValueReferences, values, nValues)) return fmi3Error;
    fmi3Status status = fmi3OK;
    for (size_t i = 0; i < nValueReferences; ++i)
        if (model_set_real(&c->m, valueReferences[i], values[i]) != 0) {
            logmsg(c, fmi3Error, "fmi3SetFloat64: %s", c->m.msg);
            status = fmi3Error;
        }
    return status;
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         fmi3String values[], size_t nValues)
{
    BEGIN(fmi3GetString, ANY_PHASE)
    if (!scalar_args(c, "fmi3GetString", valueReferences, nValueReferences, values, nValues)) return fmi3Error;
    fmi3Status status = fmi3OK;
    for (size_t i = 0; i < nValueReferences; ++i)
        if (model_get_string(&c->m, valueReferences[i], &values[i]) != 0) {
            logmsg(c, fmi3Error, "fmi3GetString: %s", c->m.msg);
            status = fmi3Error;
        }
    return status;
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const fmi3String values[], size_t nValues)
{
    BEGIN(fmi3SetString, PhaseInstantiated | PhaseInitializationMode)
    if (!scalar_args(c, "fmi3SetString", valueReferences, nValueReferences, values, nValues)) return fmi3Error;
    fmi3Status status = fmi3OK;
    for (size_t i = 0; i < nValueReferences; ++i)
        if (model_set_string(&c->m, valueReferences[i], values[i]) != 0) {
            logmsg(c, fmi3Error, "fmi3SetString: %s", c->m.msg);
            status = fmi3Error;
        }
    return status;
}

/* Int64 access: the Enumeration preset (FMI 3.0 section 2.4.7.4: enumerations through fmi3Get/SetInt64) */
fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int64 values[], size_t nValues)
{
    BEGIN(fmi3GetInt64, ANY_PHASE)
    if (!scalar_args(c, "fmi3GetInt64", valueReferences, nValueReferences, values, nValues)) return fmi3Error;
    fmi3Status status = fmi3OK;
    for (size_t i = 0; i < nValueReferences; ++i) {
        int v = 0;
        if (model_get_integer(&c->m, valueReferences[i], &v) != 0) {
            logmsg(c, fmi3Error, "fmi3GetInt64: %s", c->m.msg);
            status = fmi3Error;
        }
        values[i] = v;
    }
    return status;
}

fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int64 values[], size_t nValues)
{
    BEGIN(fmi3SetInt64, PhaseInstantiated | PhaseInitializationMode)
    if (!scalar_args(c, "fmi3SetInt64", valueReferences, nValueReferences, values, nValues)) return fmi3Error;
    fmi3Status status = fmi3OK;
    for (size_t i = 0; i < nValueReferences; ++i)
        if (model_set_integer(&c->m, valueReferences[i], (long long)values[i]) != 0) {
            logmsg(c, fmi3Error, "fmi3SetInt64: %s", c->m.msg);
            status = fmi3Error;
        }
    return status;
}

static fmi3Status no_variables(fmi3Instance instance, size_t nvr, const char *function, const char *type)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (nvr == 0) return fmi3OK;
    logmsg(c, fmi3Error, "%s: this FMU has no %s variables", function, type);
    return fmi3Error;
}

#include "fmi3_no_variables.h"     /* fmi3Get/Set of the types this FMU has no variables of */

static fmi3Status not_provided(fmi3Instance instance, const char *what)
{
    Instance3 *c = (Instance3 *)instance;
    if (c) logmsg(c, fmi3Error, "%s", what);
    return fmi3Error;
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference; (void)nDependencies;
    return not_provided(instance, "variable dependencies are in modelDescription.xml, not provided at run time");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents;
    (void)dependencyKinds; (void)nDependencies;
    return not_provided(instance, "variable dependencies are in modelDescription.xml, not provided at run time");
}

/* ------------------------------------------------------------------ FMU state */
#define STATE_MAGIC 0x4C43563FU          /* "LCV?" for FMI 3 */
typedef struct {
    unsigned magic;
    unsigned size;
    char token[64];
    ModelState s;
} Snapshot;

static int snapshot_ok(Instance3 *c, const Snapshot *snap)
{
    if (snap->magic != STATE_MAGIC || snap->size != sizeof(Snapshot) ||
        memchr(snap->token, '\0', sizeof snap->token) == NULL || strcmp(snap->token, LCV_GUID) != 0) {
        logmsg(c, fmi3Error, "the FMU state was not written by this FMU (another model or version)");
        return 0;
    }
    if (model_check_state(&c->m, &snap->s) != 0) {
        logmsg(c, fmi3Error, "%s", c->m.msg);
        return 0;
    }
    return 1;
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!FMUState) { logmsg(c, fmi3Error, "fmi3GetFMUState: null pointer"); return fmi3Error; }
    Snapshot *snap = (Snapshot *)(*FMUState);
    if (!snap) {
        snap = (Snapshot *)calloc(1, sizeof(Snapshot));
        if (!snap) { logmsg(c, fmi3Error, "fmi3GetFMUState: out of memory"); return fmi3Error; }
    }
    snap->magic = STATE_MAGIC;
    snap->size = (unsigned)sizeof(Snapshot);
    memset(snap->token, 0, sizeof snap->token);
    snprintf(snap->token, sizeof snap->token, "%s", LCV_GUID);
    snap->s = c->m.s;
    *FMUState = snap;
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    const Snapshot *snap = (const Snapshot *)FMUState;
    if (!snap) { logmsg(c, fmi3Error, "fmi3SetFMUState: null state"); return fmi3Error; }
    if (!snapshot_ok(c, snap)) return fmi3Error;
    ModelState before = c->m.s;
    c->m.s = snap->s;
    model_state_restored(&c->m, &before);
    return fmi3OK;
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!FMUState) { logmsg(c, fmi3Error, "fmi3FreeFMUState: null pointer"); return fmi3Error; }
    free(*FMUState);
    *FMUState = NULL;
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!FMUState || !size) { logmsg(c, fmi3Error, "fmi3SerializedFMUStateSize: null pointer"); return fmi3Error; }
    *size = sizeof(Snapshot);
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!FMUState || !serializedState) { logmsg(c, fmi3Error, "fmi3SerializeFMUState: null pointer"); return fmi3Error; }
    if (size < sizeof(Snapshot)) {
        logmsg(c, fmi3Error, "fmi3SerializeFMUState: %u bytes given, %u needed", (unsigned)size,
               (unsigned)sizeof(Snapshot));
        return fmi3Error;
    }
    memcpy(serializedState, FMUState, sizeof(Snapshot));
    return fmi3OK;
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!serializedState || !FMUState) {
        logmsg(c, fmi3Error, "fmi3DeserializeFMUState: null pointer");
        return fmi3Error;
    }
    if (size != sizeof(Snapshot)) {
        logmsg(c, fmi3Error, "serialized FMU state of %u bytes: expected %u", (unsigned)size, (unsigned)sizeof(Snapshot));
        return fmi3Error;
    }
    Snapshot tmp;
    memcpy(&tmp, serializedState, sizeof tmp);
    if (!snapshot_ok(c, &tmp)) return fmi3Error;
    Snapshot *snap = (Snapshot *)(*FMUState);
    if (!snap) {
        snap = (Snapshot *)malloc(sizeof(Snapshot));
        if (!snap) { logmsg(c, fmi3Error, "fmi3DeserializeFMUState: out of memory"); return fmi3Error; }
    }
    *snap = tmp;
    *FMUState = snap;
    return fmi3OK;
}

/* ------------------------------------------------------------------ not provided */
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    BEGIN(fmi3GetDirectionalDerivative, PhaseInitializationMode | RUNNING | PhaseTerminated | PhaseError)
    if (nSeed != nKnowns || nSensitivity != nUnknowns) {
        logmsg(c, fmi3Error, "fmi3GetDirectionalDerivative: %u seeds for %u knowns, %u sensitivities for %u unknowns "
               "(every variable is a scalar)", (unsigned)nSeed, (unsigned)nKnowns, (unsigned)nSensitivity,
               (unsigned)nUnknowns);
        return fmi3Error;
    }
    if (nUnknowns == 0) return fmi3OK;
    if (!unknowns || !sensitivity || (nKnowns > 0 && (!knowns || !seed))) {
        logmsg(c, fmi3Error, "fmi3GetDirectionalDerivative: null array");
        return fmi3Error;
    }
    if (model_directional(&c->m, unknowns, nUnknowns, knowns, nKnowns, seed, sensitivity) != 0) {
        logmsg(c, fmi3Error, "%s", c->m.msg);
        return fmi3Error;
    }
    return fmi3OK;
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return not_provided(instance, "adjoint derivatives are not provided");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    return not_provided(instance, "this FMU has no structural parameters (no configuration mode)");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    return not_provided(instance, "this FMU has no structural parameters (no configuration mode)");
}

#define NO_CLOCKS "this FMU has no clocks"
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return not_provided(instance, NO_CLOCKS);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    Instance3 *c = (Instance3 *)instance;
    return c ? fmi3OK : fmi3Error;          /* no discrete states */
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference; (void)activationTime;
    return not_provided(instance, "this FMU offers no Scheduled Execution");
}

/* ------------------------------------------------------------------ events (none) */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    BEGIN(fmi3UpdateDiscreteStates, PhaseEventMode)         /* Event Mode only (Co-Simulation has none here) */
    if (!discreteStatesNeedUpdate || !terminateSimulation || !nominalsOfContinuousStatesChanged ||
        !valuesOfContinuousStatesChanged || !nextEventTimeDefined || !nextEventTime) {
        logmsg(c, fmi3Error, "fmi3UpdateDiscreteStates: null pointer");
        return fmi3Error;
    }
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False;
    *nextEventTime = 0.0;
    return fmi3OK;
}

/* ------------------------------------------------------------------ Model Exchange */
#define MASK_STATES (PhaseInitializationMode | PhaseEventMode | PhaseContinuousTimeMode | PhaseTerminated | PhaseError)

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    BEGIN(fmi3EnterContinuousTimeMode, PhaseEventMode)
    if (!c->m.model_exchange) {
        logmsg(c, fmi3Error, "fmi3EnterContinuousTimeMode: the instance is a co-simulation");
        return fmi3Error;
    }
    c->m.s.phase = PhaseContinuousTimeMode;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN(fmi3CompletedIntegratorStep, PhaseContinuousTimeMode)
    if (!enterEventMode || !terminateSimulation) {
        logmsg(c, fmi3Error, "fmi3CompletedIntegratorStep: null pointer");
        return fmi3Error;
    }
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    BEGIN(fmi3SetTime, PhaseEventMode | PhaseContinuousTimeMode)
    if (!isfinite(time)) { logmsg(c, fmi3Error, "fmi3SetTime: time is not finite (%g)", time); return fmi3Error; }
    c->m.s.time = time;
    return fmi3OK;
}

static int states_arg(Instance3 *c, const char *function, const void *x, size_t nx)
{
    if (nx != LCV_N_ME_STATES) {
        logmsg(c, fmi3Error, "%s: %u states given, this FMU has %u", function, (unsigned)nx,
               (unsigned)LCV_N_ME_STATES);
        return 0;
    }
    if (!x) { logmsg(c, fmi3Error, "%s: null array", function); return 0; }
    return 1;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    BEGIN(fmi3SetContinuousStates, PhaseContinuousTimeMode)
    if (!states_arg(c, "fmi3SetContinuousStates", continuousStates, nContinuousStates)) return fmi3Error;
    for (size_t i = 0; i < nContinuousStates; ++i)
        if (!isfinite(continuousStates[i])) {
            logmsg(c, fmi3Error, "fmi3SetContinuousStates: state %s is not finite (%g); the states are unchanged",
                   LCV_VARIABLE_NAME(LCV_ME_STATE_VR_OF(i)), continuousStates[i]);
            return fmi3Error;
        }
    model_set_states(&c->m, continuousStates, nContinuousStates);
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    BEGIN(fmi3GetContinuousStates, MASK_STATES)
    if (!states_arg(c, "fmi3GetContinuousStates", continuousStates, nContinuousStates)) return fmi3Error;
    model_get_states(&c->m, continuousStates, nContinuousStates);
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    BEGIN(fmi3GetContinuousStateDerivatives, MASK_STATES)
    if (!states_arg(c, "fmi3GetContinuousStateDerivatives", derivatives, nContinuousStates)) return fmi3Error;
    int r = model_derivatives(&c->m, derivatives, nContinuousStates);
    if (r < 0) { logmsg(c, fmi3Error, "%s", c->m.msg); return fmi3Error; }
    if (r > 0) logmsg(c, fmi3Warning, "%s", c->m.msg);
    return r > 0 ? fmi3Warning : fmi3OK;
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    BEGIN(fmi3GetNominalsOfContinuousStates, PhaseInstantiated | MASK_STATES)
    if (!states_arg(c, "fmi3GetNominalsOfContinuousStates", nominals, nContinuousStates)) return fmi3Error;
    model_get_nominals(&c->m, nominals, nContinuousStates);     /* each state's physical scale */
    return fmi3OK;
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    BEGIN(fmi3GetEventIndicators, MASK_STATES)
    (void)eventIndicators;
    if (nEventIndicators != 0) {
        logmsg(c, fmi3Error, "fmi3GetEventIndicators: this FMU has no event indicators");
        return fmi3Error;
    }
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!nEventIndicators) { logmsg(c, fmi3Error, "fmi3GetNumberOfEventIndicators: null pointer"); return fmi3Error; }
    *nEventIndicators = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!nContinuousStates) { logmsg(c, fmi3Error, "fmi3GetNumberOfContinuousStates: null pointer"); return fmi3Error; }
    *nContinuousStates = LCV_N_ME_STATES;
    return fmi3OK;
}

/* ------------------------------------------------------------------ Co-Simulation */
fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    BEGIN(fmi3EnterStepMode, PhaseEventMode)                /* leaves a Co-Simulation's Event Mode: never used here */
    if (c->m.model_exchange) { logmsg(c, fmi3Error, "fmi3EnterStepMode: the instance is a model exchange"); return fmi3Error; }
    c->m.s.phase = PhaseStepComplete;
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)valueReferences; (void)nValueReferences; (void)orders; (void)values; (void)nValues;
    return not_provided(instance, "output derivatives are not provided");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)currentCommunicationPoint; (void)noSetFMUStatePriorToCurrentPoint;
    Instance3 *c = (Instance3 *)instance;
    if (!c) return fmi3Error;
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime) {
        logmsg(c, fmi3Error, "fmi3DoStep: null pointer");
        return fmi3Error;
    }
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = c->m.s.time;
    if (c->m.s.phase == PhaseError) {
        logmsg(c, fmi3Error, "%s; every step will be refused (fmi3Reset to start again)", c->m.s.error);
        return fmi3Error;
    }
    if (!allowed(c, "fmi3DoStep", PhaseStepComplete)) return fmi3Error;
    if (!isfinite(currentCommunicationPoint)) {
        logmsg(c, fmi3Error, "fmi3DoStep: currentCommunicationPoint is not finite (%g)", currentCommunicationPoint);
        return fmi3Error;
    }
    int r = model_do_step(&c->m, communicationStepSize);
    if (r < 0) { logmsg(c, fmi3Error, "%s", c->m.msg); return fmi3Error; }
    if (r > 0) logmsg(c, fmi3Warning, "%s", c->m.msg);
    *lastSuccessfulTime = c->m.s.time;
    return r > 0 ? fmi3Warning : fmi3OK;    /* a clamped speed: the Python FMU's status too */
}
