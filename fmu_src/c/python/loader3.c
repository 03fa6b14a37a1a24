/*
 * The binary of the FMI 3.0 Python FMU (LCV3.fmu and `lcv fmu --fmi 3 --kind python`): a
 * loader in front of pythonfmu3's export library, as loader.c is in front of pythonfmu's.
 *
 * 1. Python in any host: pyruntime.c finds the process's Python or starts the one the FMU
 *    was built with (no LD_PRELOAD: pythonfmu3's library alone fails in a plain C host with
 *    "undefined symbol: _Py_NoneStruct"), then loads pythonfmu3's library next to this one.
 * 2. Only what pythonfmu3 does safely is forwarded, with arguments checked first: the
 *    resource path (an existing folder holding the slave module), value references against
 *    the interface table (loader_config.h), null arrays, counts, serialized states.  Every
 *    other call is answered here: pythonfmu3 0.3.4 throws a C++ exception out of an extern "C"
 *    function for the types it does not implement (std::terminate: the host aborts),
 *    dereferences a NULL instance, and has no Model Exchange or clocks behind its symbols.
 * 3. Statuses: a call that logged an error returns fmi3Error (the slave never raises, it
 *    logs); pythonfmu3's Fatal becomes fmi3Error and the instance is not called again;
 *    errors and warnings reach the host whatever the logging flag.
 * 4. The state machine of the native FMU (fmi3_api.c, Co-Simulation): a call outside its
 *    phases is refused.  The phase is part of an FMU state (one byte after its serialization).
 */
#define _POSIX_C_SOURCE 200809L   /* strdup */
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "fmu_common.h"
#include "loader_config.h"
#include "pyruntime.h"

/* ------------------------------------------------------------------ the forwarded library */
#define FORWARDED(X) \
    X(fmi3InstantiateCoSimulation) X(fmi3FreeInstance) X(fmi3EnterInitializationMode) \
    X(fmi3ExitInitializationMode) X(fmi3Terminate) X(fmi3Reset) X(fmi3GetFloat64) X(fmi3SetFloat64) \
    X(fmi3GetInt64) X(fmi3SetInt64) X(fmi3GetString) X(fmi3SetString) X(fmi3DoStep) X(fmi3GetFMUState) \
    X(fmi3SetFMUState) X(fmi3FreeFMUState) X(fmi3SerializedFMUStateSize) X(fmi3SerializeFMUState) \
    X(fmi3DeserializeFMUState)

#include "loader_forward.inc"         /* p_<F>, resolve(): the Python runtime and the library, once */

/* phases (fmu_common.h): Co-Simulation without event mode */
#define PhaseStepMode PhaseStepComplete
#define BEFORE_INIT (PhaseInstantiated | PhaseInitializationMode)

typedef struct {
    fmi3Instance inner;
    fmi3InstanceEnvironment host_env;
    fmi3LogMessageCallback host_log;
    int worst;                            /* worst status logged during the current call */
    int dead;                             /* pythonfmu3 returned fmi3Fatal: never call it again */
    int logging_on;
    int phase;
    double time;                          /* the independent variable: the start, then each step's end */
    char *name;
    char *folder;
    char *alias;                          /* a symlink to it pythonfmu3 reads as is, or NULL (pyruntime.h) */
} Wrapper;

/* the FMI 3 statuses, for the code both loaders share (loader_guard.inc, loader_state.inc) */
#define LS_STATUS fmi3Status
#define LS_OK fmi3OK
#define LS_WARNING fmi3Warning
#define LS_DISCARD fmi3Discard
#define LS_ERROR fmi3Error
#define LS_FATAL fmi3Fatal
#define LS_FREE_INSTANCE "fmi3FreeInstance"

/* ------------------------------------------------------------------ logging */
static void say(Wrapper *w, fmi3Status status, const char *fmt, ...)
{
    char text[2400];
    va_list ap;
    if (!w || !w->host_log || (!w->logging_on && status < fmi3Warning)) return;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    w->host_log(w->host_env, status, log_category(status), text);
}

static void own_logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    Wrapper *w = (Wrapper *)env;
    if (!w) return;
    if ((int)status > w->worst) w->worst = (int)status;
    if (!w->host_log || (!w->logging_on && status < fmi3Warning)) return;
    w->host_log(w->host_env, status, category && *category ? category : log_category(status),
                message ? message : "");
}

#include "loader_guard.inc"           /* outcome(), usable() */

#define BEGIN(F, MASK) \
    Wrapper *w = (Wrapper *)instance; \
    if (!usable(w, #F, (MASK))) return fmi3Error;

/* value references of the kinds ``kinds`` (loader_config.h: P parameter, I input, O output,
   E the Enumeration), one value each */
static int check_vrs(Wrapper *w, const fmi3ValueReference vr[], size_t nvr, const void *values, size_t nValues,
                     const char *kinds, const char *function, const char *what)
{
    if (nvr == 0) return 1;
    if (!vr || !values) { say(w, fmi3Error, "%s: null array", function); return 0; }
    if (nValues != nvr) {
        say(w, fmi3Error, "%s: %u values for %u value references (every variable is a scalar)", function,
            (unsigned)nValues, (unsigned)nvr);
        return 0;
    }
    for (size_t i = 0; i < nvr; ++i) {
        if (vr[i] >= LOADER_N_VARIABLES || !strchr(kinds, LOADER_VARIABLE_KIND[vr[i]])) {
            say(w, fmi3Error, "%s: %u is not the value reference of %s", function, vr[i], what);
            return 0;
        }
    }
    return 1;
}

/* ------------------------------------------------------------------ inquiry, instances */
const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    BEGIN(fmi3SetDebugLogging, ANY_PHASE)
    if (nCategories > 0 && !categories) { say(w, fmi3Error, "fmi3SetDebugLogging: null array"); return fmi3Error; }
    w->logging_on = loggingOn ? 1 : 0;    /* pythonfmu3 logs every error and warning; the loader filters */
    return fmi3OK;
}

static void say_once(fmi3InstanceEnvironment env, fmi3LogMessageCallback log, const char *text)
{
    if (log) log(env, fmi3Error, "logStatusError", text);
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
    (void)earlyReturnAllowed; (void)requiredIntermediateVariables; (void)intermediateUpdate;
    char why[2400];
    const char *name = instanceName ? instanceName : LOADER_MODEL_IDENTIFIER;
    if (!pyrt_valid_utf8((const unsigned char *)name)) {
        /* pythonfmu3 decodes the name as UTF-8 and takes the host down on a failure */
        say_once(instanceEnvironment, logMessage, "fmi3InstantiateCoSimulation: the instanceName is not UTF-8 text; "
                 "give a name of UTF-8 text");
        return NULL;
    }
    if (!instantiationToken || strcmp(instantiationToken, LOADER_GUID) != 0) {
        say_once(instanceEnvironment, logMessage,
                 "instantiation token mismatch: the modelDescription.xml does not belong to this binary");
        return NULL;
    }
    if (eventModeUsed) {
        say_once(instanceEnvironment, logMessage, LOADER_MODEL_IDENTIFIER " has no event mode (hasEventMode=false)");
        return NULL;
    }
    if (nRequiredIntermediateVariables > 0) {
        say_once(instanceEnvironment, logMessage, LOADER_MODEL_IDENTIFIER " provides no intermediate update");
        return NULL;
    }
    /* the resource path: an existing folder (with or without its trailing '/') holding the slave module */
    char folder[4096], module[4200];
    if (!resourcePath || !*resourcePath || strlen(resourcePath) >= sizeof folder) {
        say_once(instanceEnvironment, logMessage, "resourcePath is NULL, empty or too long");
        return NULL;
    }
    snprintf(folder, sizeof folder, "%s", resourcePath);
    size_t j = strlen(folder);
    while (j > 1 && folder[j - 1] == '/') folder[--j] = '\0';
    snprintf(module, sizeof module, "%s/slavemodule.txt", folder);
    if (folder[0] != '/' || !pyrt_valid_utf8((const unsigned char *)folder) ||
        !pyrt_is_dir(folder) || !pyrt_is_file(module)) {
        snprintf(why, sizeof why, "the resourcePath %.1000s is not this FMU's resources folder (an absolute path "
                 "of UTF-8 text holding slavemodule.txt)", folder);
        say_once(instanceEnvironment, logMessage, why);
        return NULL;
    }
    pthread_once(&resolved_once, resolve);
    if (load_error) {
        say_once(instanceEnvironment, logMessage, load_error);
        return NULL;
    }
    char alias[128] = "";
    if (pyrt_needs_alias(folder) && !pyrt_resource_alias(folder, alias, sizeof alias, why, sizeof why)) {
        say_once(instanceEnvironment, logMessage, why);
        return NULL;
    }
    Wrapper *w = (Wrapper *)calloc(1, sizeof(Wrapper));
    if (!w || !(w->name = strdup(name)) || !(w->folder = strdup(folder)) || (*alias && !(w->alias = strdup(alias)))) {
        if (w) { free(w->name); free(w->folder); }
        free(w);
        pyrt_resource_alias_free(alias);
        say_once(instanceEnvironment, logMessage, "out of memory");
        return NULL;
    }
    w->host_env = instanceEnvironment;
    w->host_log = logMessage;
    w->logging_on = loggingOn ? 1 : 0;
    w->phase = PhaseInstantiated;
    pyrt_instance_added();
    /* logging on inside: the loader filters what the host sees */
    w->inner = p_fmi3InstantiateCoSimulation(w->name, instantiationToken, w->alias ? w->alias : folder, visible,
                                             fmi3True, fmi3False,
                                             fmi3False, NULL, 0, w, own_logger, NULL);
    if (!w->inner) {
        say(w, fmi3Error, "fmi3InstantiateCoSimulation: the Python model could not be instantiated");
        fmi3FreeInstance(w);
        return NULL;
    }
    return w;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    say_once(instanceEnvironment, logMessage, LOADER_MODEL_IDENTIFIER " is a Co-Simulation FMU (for Model Exchange "
             "use the native FMU, lcv fmu --fmi 3 --kind native)");
    return NULL;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    say_once(instanceEnvironment, logMessage, LOADER_MODEL_IDENTIFIER " does not support Scheduled Execution");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    Wrapper *w = (Wrapper *)instance;
    if (!w) return;
    if (w->inner && !w->dead) p_fmi3FreeInstance(w->inner);
    pyrt_instance_freed(w->folder);
    pyrt_resource_alias_free(w->alias);
    free(w->name);
    free(w->folder);
    free(w->alias);
    free(w);
}

/* ------------------------------------------------------------------ phases */
static fmi3Status transition(Wrapper *w, fmi3Status s, const char *function, int ok_phase, int fail_phase)
{
    s = outcome(w, s, function);
    if (s <= fmi3Warning) w->phase = ok_phase;
    else if (fail_phase) w->phase = fail_phase;
    return s;
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    BEGIN(fmi3EnterInitializationMode, PhaseInstantiated)
    if (!isfinite(startTime)) {
        say(w, fmi3Error, "fmi3EnterInitializationMode: startTime is not finite (%g)", startTime);
        return fmi3Error;
    }
    w->time = startTime;
    return transition(w, p_fmi3EnterInitializationMode(w->inner, toleranceDefined, tolerance, startTime,
                                                       stopTimeDefined, stopTime),
                      "fmi3EnterInitializationMode", PhaseInitializationMode, 0);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    BEGIN(fmi3ExitInitializationMode, PhaseInitializationMode)
    return transition(w, p_fmi3ExitInitializationMode(w->inner), "fmi3ExitInitializationMode", PhaseStepMode,
                      PhaseError);
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    BEGIN(fmi3Terminate, PhaseStepMode | PhaseError)
    return transition(w, p_fmi3Terminate(w->inner), "fmi3Terminate", PhaseTerminated, 0);
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    BEGIN(fmi3Reset, ANY_PHASE)
    return transition(w, p_fmi3Reset(w->inner), "fmi3Reset", PhaseInstantiated, 0);
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime)
{
    BEGIN(fmi3DoStep, PhaseStepMode | PhaseError)     /* in Error the slave names the cause */
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime) {
        say(w, fmi3Error, "fmi3DoStep: null pointer");
        return fmi3Error;
    }
    if (!isfinite(currentCommunicationPoint)) {
        *eventHandlingNeeded = *terminateSimulation = *earlyReturn = fmi3False;
        *lastSuccessfulTime = w->time;
        say(w, fmi3Error, "fmi3DoStep: currentCommunicationPoint is not finite (%g)", currentCommunicationPoint);
        return fmi3Error;
    }
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    fmi3Float64 last = currentCommunicationPoint;
    fmi3Status s = outcome(w, p_fmi3DoStep(w->inner, currentCommunicationPoint, communicationStepSize,
                                           noSetFMUStatePriorToCurrentPoint, &event, &terminate, &early, &last),
                           "fmi3DoStep");
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = s <= fmi3Warning ? currentCommunicationPoint + communicationStepSize
                                           : currentCommunicationPoint;
    w->time = *lastSuccessfulTime;
    return s;
}

/* ------------------------------------------------------------------ values */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues)
{
    BEGIN(fmi3GetFloat64, ANY_PHASE)
    /* the independent variable time is the loader's; the rest is the slave's */
    size_t n_time = 0;
    for (size_t i = 0; valueReferences && values && i < nValueReferences && nValues == nValueReferences; ++i)
        if (valueReferences[i] == LOADER_TIME_VR) { values[i] = w->time; ++n_time; }
    if (n_time == 0 || n_time == nValueReferences) {
        if (n_time) return fmi3OK;
        if (!check_vrs(w, valueReferences, nValueReferences, values, nValues, "PIO", "fmi3GetFloat64",
                       "a Float64 variable")) return fmi3Error;
        if (nValueReferences == 0) return fmi3OK;
        return outcome(w, p_fmi3GetFloat64(w->inner, valueReferences, nValueReferences, values, nValues),
                       "fmi3GetFloat64");
    }
    size_t n = nValueReferences - n_time;
    fmi3ValueReference *vr = (fmi3ValueReference *)malloc(n * sizeof *vr);
    fmi3Float64 *v = (fmi3Float64 *)malloc(n * sizeof *v);
    if (!vr || !v) { free(vr); free(v); say(w, fmi3Error, "fmi3GetFloat64: out of memory"); return fmi3Error; }
    for (size_t i = 0, k = 0; i < nValueReferences; ++i)
        if (valueReferences[i] != LOADER_TIME_VR) vr[k++] = valueReferences[i];
    fmi3Status s = fmi3Error;
    if (check_vrs(w, vr, n, v, n, "PIO", "fmi3GetFloat64", "a Float64 variable")) {
        s = outcome(w, p_fmi3GetFloat64(w->inner, vr, n, v, n), "fmi3GetFloat64");
        for (size_t i = 0, k = 0; i < nValueReferences; ++i)
            if (valueReferences[i] != LOADER_TIME_VR) values[i] = v[k++];
    }
    free(vr);
    free(v);
    return s;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues)
{
    BEGIN(fmi3SetFloat64, BEFORE_INIT | PhaseStepMode)
    if (!check_vrs(w, valueReferences, nValueReferences, values, nValues, "PI", "fmi3SetFloat64",
                   "an input or a Float64 parameter")) return fmi3Error;
    if (nValueReferences == 0) return fmi3OK;
    return outcome(w, p_fmi3SetFloat64(w->inner, valueReferences, nValueReferences, values, nValues),
                   "fmi3SetFloat64");
}

fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int64 values[], size_t nValues)
{
    BEGIN(fmi3GetInt64, ANY_PHASE)
    if (!check_vrs(w, valueReferences, nValueReferences, values, nValues, "E", "fmi3GetInt64",
                   "an Enumeration variable")) return fmi3Error;
    if (nValueReferences == 0) return fmi3OK;
    return outcome(w, p_fmi3GetInt64(w->inner, valueReferences, nValueReferences, values, nValues), "fmi3GetInt64");
}

fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int64 values[], size_t nValues)
{
    BEGIN(fmi3SetInt64, BEFORE_INIT)
    if (!check_vrs(w, valueReferences, nValueReferences, values, nValues, "E", "fmi3SetInt64",
                   "an Enumeration variable")) return fmi3Error;
    if (nValueReferences == 0) return fmi3OK;
    return outcome(w, p_fmi3SetInt64(w->inner, valueReferences, nValueReferences, values, nValues), "fmi3SetInt64");
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         fmi3String values[], size_t nValues)
{
    BEGIN(fmi3GetString, ANY_PHASE)
    if (!check_vrs(w, valueReferences, nValueReferences, values, nValues, "E", "fmi3GetString",
                   "preset (the Enumeration, also by name)")) return fmi3Error;
    if (nValueReferences == 0) return fmi3OK;
    return outcome(w, p_fmi3GetString(w->inner, valueReferences, nValueReferences, values, nValues),
                   "fmi3GetString");
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const fmi3String values[], size_t nValues)
{
    BEGIN(fmi3SetString, BEFORE_INIT)
    if (!check_vrs(w, valueReferences, nValueReferences, values, nValues, "E", "fmi3SetString",
                   "preset (the Enumeration, also by name)")) return fmi3Error;
    for (size_t i = 0; i < nValueReferences; ++i) {
        if (!values[i]) { say(w, fmi3Error, "fmi3SetString: null string"); return fmi3Error; }
        if (!pyrt_valid_utf8((const unsigned char *)values[i])) {
            say(w, fmi3Error, "fmi3SetString: the value is not UTF-8 text");
            return fmi3Error;
        }
    }
    if (nValueReferences == 0) return fmi3OK;
    return outcome(w, p_fmi3SetString(w->inner, valueReferences, nValueReferences, values, nValues),
                   "fmi3SetString");
}

static fmi3Status no_variables(fmi3Instance instance, size_t nvr, const char *function, const char *type)
{
    Wrapper *w = (Wrapper *)instance;
    if (!usable(w, function, ANY_PHASE)) return fmi3Error;
    if (nvr == 0) return fmi3OK;
    say(w, fmi3Error, "%s: this FMU has no %s variables", function, type);
    return fmi3Error;
}

#include "fmi3_no_variables.h"     /* fmi3Get/Set of the types this FMU has no variables of */

/* ------------------------------------------------------------------ what a Co-Simulation FMU without events lacks */
static fmi3Status unsupported(fmi3Instance instance, const char *function, const char *why)
{
    Wrapper *w = (Wrapper *)instance;
    if (!w) return fmi3Error;
    say(w, fmi3Error, "%s: %s", function, why);
    return fmi3Error;
}

#define NO_EVENTS "this FMU has no event mode, clocks or Model Exchange interface"

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference; (void)nDependencies;
    return unsupported(instance, "fmi3GetNumberOfVariableDependencies", "dependencies are in modelDescription.xml");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents;
    (void)dependencyKinds; (void)nDependencies;
    return unsupported(instance, "fmi3GetVariableDependencies", "dependencies are in modelDescription.xml");
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetDirectionalDerivative",
                       "directional derivatives are provided by the native FMU, not the Python one");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetAdjointDerivative", "adjoint derivatives are not provided");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{ return unsupported(instance, "fmi3EnterConfigurationMode", "this FMU has no structural parameters"); }

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{ return unsupported(instance, "fmi3ExitConfigurationMode", "this FMU has no structural parameters"); }

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalDecimal", NO_EVENTS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalFraction", NO_EVENTS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return unsupported(instance, "fmi3GetShiftDecimal", NO_EVENTS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return unsupported(instance, "fmi3GetShiftFraction", NO_EVENTS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    return unsupported(instance, "fmi3SetIntervalDecimal", NO_EVENTS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return unsupported(instance, "fmi3SetIntervalFraction", NO_EVENTS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return unsupported(instance, "fmi3SetShiftDecimal", NO_EVENTS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return unsupported(instance, "fmi3SetShiftFraction", NO_EVENTS);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{ return unsupported(instance, "fmi3EvaluateDiscreteStates", NO_EVENTS); }

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference; (void)activationTime;
    return unsupported(instance, "fmi3ActivateModelPartition", NO_EVENTS);
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{ return unsupported(instance, "fmi3EnterEventMode", NO_EVENTS); }

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate; (void)terminateSimulation; (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged; (void)nextEventTimeDefined; (void)nextEventTime;
    return unsupported(instance, "fmi3UpdateDiscreteStates", NO_EVENTS);
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{ return unsupported(instance, "fmi3EnterContinuousTimeMode", NO_EVENTS); }

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    return unsupported(instance, "fmi3CompletedIntegratorStep", NO_EVENTS);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{ (void)time; return unsupported(instance, "fmi3SetTime", NO_EVENTS); }

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates; (void)nContinuousStates;
    return unsupported(instance, "fmi3SetContinuousStates", NO_EVENTS);
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates; (void)nContinuousStates;
    return unsupported(instance, "fmi3GetContinuousStates", NO_EVENTS);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    (void)derivatives; (void)nContinuousStates;
    return unsupported(instance, "fmi3GetContinuousStateDerivatives", NO_EVENTS);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    (void)nominals; (void)nContinuousStates;
    return unsupported(instance, "fmi3GetNominalsOfContinuousStates", NO_EVENTS);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    (void)eventIndicators; (void)nEventIndicators;
    return unsupported(instance, "fmi3GetEventIndicators", NO_EVENTS);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    Wrapper *w = (Wrapper *)instance;
    if (!w || !nEventIndicators) return fmi3Error;
    *nEventIndicators = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    Wrapper *w = (Wrapper *)instance;
    if (!w || !nContinuousStates) return fmi3Error;
    *nContinuousStates = 0;
    return fmi3OK;
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{ return unsupported(instance, "fmi3EnterStepMode", NO_EVENTS); }

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)valueReferences; (void)nValueReferences; (void)orders; (void)values; (void)nValues;
    return unsupported(instance, "fmi3GetOutputDerivatives", "output derivatives are not provided");
}

/* ------------------------------------------------------------------ FMU state */
/* pythonfmu3's state of the slave, the phase and the time (loader_state.inc, shared with loader.c) */
#define LS_STATE fmi3FMUState
#define LS_BYTE fmi3Byte
#define LS_TAG 0x4C435633U                /* "LCV3" */
#define LS_KEEPS_TIME 1
#define LS_GET p_fmi3GetFMUState
#define LS_SET p_fmi3SetFMUState
#define LS_FREE p_fmi3FreeFMUState
#define LS_SIZE p_fmi3SerializedFMUStateSize
#define LS_SERIALIZE p_fmi3SerializeFMUState
#define LS_DESERIALIZE p_fmi3DeserializeFMUState
#include "loader_state.inc"

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    BEGIN(fmi3GetFMUState, ANY_PHASE)
    return state_get(w, FMUState, "fmi3GetFMUState");
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    BEGIN(fmi3SetFMUState, ANY_PHASE)
    return state_set(w, FMUState, "fmi3SetFMUState");
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    BEGIN(fmi3FreeFMUState, ANY_PHASE)
    return state_free(w, FMUState, "fmi3FreeFMUState");
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    BEGIN(fmi3SerializedFMUStateSize, ANY_PHASE)
    return state_size(w, FMUState, size, "fmi3SerializedFMUStateSize");
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size)
{
    BEGIN(fmi3SerializeFMUState, ANY_PHASE)
    return state_serialize(w, FMUState, serializedState, size, "fmi3SerializeFMUState");
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    BEGIN(fmi3DeserializeFMUState, ANY_PHASE)
    return state_deserialize(w, serializedState, size, FMUState, "fmi3DeserializeFMUState");
}
