/*
 * The binary of the pythonfmu FMU (LCV.fmu and vehicle FMUs built with --kind python):
 * a small loader in front of pythonfmu's export library.
 *
 * 1. Python in any host.  pythonfmu's library needs a Python interpreter in the process
 *    (a plain C host fails with "undefined symbol: _Py_NoneStruct").  On the first
 *    fmi2Instantiate the loader looks for one (Py_IsInitialized); if the process has
 *    none it loads the libpython recorded when the FMU was built (RTLD_GLOBAL), starts
 *    it without signal handlers, adds the recorded site-packages (numpy), and never
 *    finalizes it (pythonfmu then never does either: no crash at exit).  Environment
 *    variables override what was recorded: LCV_FMU_LIBPYTHON, LCV_FMU_PYTHONHOME,
 *    LCV_FMU_SITE_PACKAGES.  Then it loads pythonfmu's library (next to this one) and
 *    forwards every call.
 * 2. FMI statuses.  pythonfmu can only return OK, Discard (doStep False) or Fatal (a
 *    Python exception, after which it frees the Python instance twice).  The slave
 *    never raises; it logs with fmi2Error instead, and the loader turns a call that
 *    logged an error into fmi2Error.  Value references, null arrays and serialized
 *    states are checked here against the interface table (loader_config.h, generated
 *    by lcvreport.fmu.build) before Python sees them.  If Fatal ever comes back the
 *    loader returns fmi2Error and never calls into that instance again.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>

#include "fmi2Functions.h"
#include "fmi2_shared.h"
#include "loader_config.h"

/* ------------------------------------------------------------------ the forwarded library */
#define FORWARDED(X) \
    X(fmi2Instantiate) X(fmi2FreeInstance) X(fmi2SetDebugLogging) X(fmi2SetupExperiment) \
    X(fmi2EnterInitializationMode) X(fmi2ExitInitializationMode) X(fmi2Terminate) X(fmi2Reset) \
    X(fmi2GetReal) X(fmi2GetInteger) X(fmi2GetBoolean) X(fmi2GetString) X(fmi2SetReal) X(fmi2SetInteger) \
    X(fmi2SetBoolean) X(fmi2SetString) X(fmi2GetFMUstate) X(fmi2SetFMUstate) X(fmi2FreeFMUstate) \
    X(fmi2SerializedFMUstateSize) X(fmi2SerializeFMUstate) X(fmi2DeSerializeFMUstate) X(fmi2DoStep) \
    X(fmi2GetStatus) X(fmi2GetRealStatus) X(fmi2GetIntegerStatus) X(fmi2GetBooleanStatus) X(fmi2GetStringStatus)

#define DECLARE(F) static F##TYPE *p_##F;
FORWARDED(DECLARE)
#undef DECLARE

static pthread_once_t once = PTHREAD_ONCE_INIT;
static char load_error[2048];
wchar_t *lcv_loader_python_home;   /* Py_SetPythonHome keeps the pointer: it lives as long as the process */
static void (*p_finalizePythonInterpreter)(void);

/* pythonfmu 0.7.0 keeps its interpreter state in a static std::shared_ptr, destroyed by a
   C++ static destructor at exit; its library destructor (finalizePythonInterpreter) then
   assigns to the destroyed pointer -- a use after free (valgrind: "Invalid read ... in
   finalizePythonInterpreter ... block free'd in __run_exit_handlers") that corrupts the
   heap and aborts the host at exit ("free(): corrupted unsorted chunks").  Releasing the
   state before the static destructors run (atexit handlers run in reverse order of
   registration, and this one is registered after pythonfmu's) leaves nothing to free twice. */
static void release_pythonfmu(void)
{
    if (p_finalizePythonInterpreter) p_finalizePythonInterpreter();
}

typedef struct {
    fmi2Component inner;
    fmi2CallbackFunctions host;           /* the host's callbacks */
    fmi2CallbackFunctions own;            /* ours, given to pythonfmu */
    int worst;                            /* worst status logged during the current call */
    int dead;                             /* pythonfmu returned fmi2Fatal: never call it again */
    char *name;
} Wrapper;

static const char *setting(const char *env, const char *recorded)
{
    const char *v = getenv(env);
    return v && *v ? v : recorded;
}

typedef int (*int_void_t)(void);
typedef void (*void_int_t)(int);
typedef void (*void_wstr_t)(const wchar_t *);
typedef wchar_t *(*decode_t)(const char *, size_t *);
typedef int (*run_t)(const char *);
typedef const char *(*str_void_t)(void);
typedef void *(*ptr_void_t)(void);
typedef int (*gil_ensure_t)(void);
typedef void (*gil_release_t)(int);

/* run Python code with the GIL held; returns PyRun_SimpleString's result */
static int run_python(void *py, const char *code)
{
    gil_ensure_t ensure = (gil_ensure_t)dlsym(py, "PyGILState_Ensure");
    gil_release_t release = (gil_release_t)dlsym(py, "PyGILState_Release");
    run_t run = (run_t)dlsym(py, "PyRun_SimpleString");
    if (!ensure || !release || !run) return -1;
    int g = ensure();
    int r = run(code);
    release(g);
    return r;
}

static void bring_up(void)
{
    const char *libpython = setting("LCV_FMU_LIBPYTHON", LOADER_LIBPYTHON);
    const char *home = setting("LCV_FMU_PYTHONHOME", LOADER_PYTHON_HOME);
    const char *site = setting("LCV_FMU_SITE_PACKAGES", LOADER_SITE_PACKAGES);
    void *py = RTLD_DEFAULT;
    int_void_t is_init = (int_void_t)dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    int started = 0;
    if (!is_init) {
        py = dlopen(libpython, RTLD_NOW | RTLD_GLOBAL);
        if (!py) {
            snprintf(load_error, sizeof load_error,
                     "cannot load the Python library %s recorded when this FMU was built (%s); set "
                     "LCV_FMU_LIBPYTHON to the libpython%s of a Python environment that has numpy, and "
                     "LCV_FMU_SITE_PACKAGES to its site-packages", libpython, dlerror(), LOADER_PYTHON_VERSION);
            return;
        }
        is_init = (int_void_t)dlsym(py, "Py_IsInitialized");
    }
    str_void_t version = (str_void_t)dlsym(py, "Py_GetVersion");
    if (!is_init || !version) {
        snprintf(load_error, sizeof load_error, "%s is not a Python library (set LCV_FMU_LIBPYTHON)", libpython);
        return;
    }
    if (strncmp(version(), LOADER_PYTHON_VERSION ".", strlen(LOADER_PYTHON_VERSION) + 1) != 0) {
        snprintf(load_error, sizeof load_error, "this process runs Python %.20s; the FMU was built for Python %s",
                 version(), LOADER_PYTHON_VERSION);
        return;
    }
    if (!is_init()) {
        void_wstr_t set_home = (void_wstr_t)dlsym(py, "Py_SetPythonHome");
        decode_t decode = (decode_t)dlsym(py, "Py_DecodeLocale");
        void_int_t init = (void_int_t)dlsym(py, "Py_InitializeEx");
        ptr_void_t save = (ptr_void_t)dlsym(py, "PyEval_SaveThread");
        if (!init || !save) {
            snprintf(load_error, sizeof load_error, "%s lacks Py_InitializeEx", libpython);
            return;
        }
        if (set_home && decode && home && *home) {
            lcv_loader_python_home = decode(home, NULL);
            if (lcv_loader_python_home) set_home(lcv_loader_python_home);
        }
        init(0);                     /* 0: leave the host's signal handlers alone */
        (void)save();                /* release the GIL; pythonfmu takes it per call */
        started = 1;
    }
    if (site && *site) {
        char code[4096];
        snprintf(code, sizeof code, "import sys, site\np = %s%s%s\nif p not in sys.path: site.addsitedir(p)\n",
                 "r'''", site, "'''");
        if (run_python(py, code) != 0) {
            snprintf(load_error, sizeof load_error, "cannot add %s to the Python path", site);
            return;
        }
    }
    if (run_python(py, "import numpy\n") != 0) {
        snprintf(load_error, sizeof load_error, "numpy cannot be imported by the Python in this process (%s); set "
                 "LCV_FMU_SITE_PACKAGES to the site-packages of an environment that has numpy", started ?
                 "started by the FMU" : "the host's");
        return;
    }
    Dl_info info;
    if (!dladdr((void *)&bring_up, &info) || !info.dli_fname) {
        snprintf(load_error, sizeof load_error, "cannot find the FMU's binaries folder");
        return;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s", info.dli_fname);
    char *slash = strrchr(path, '/');
    if (slash) *(slash + 1) = '\0'; else path[0] = '\0';
    strncat(path, LOADER_EXPORT_LIB, sizeof path - strlen(path) - 1);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        snprintf(load_error, sizeof load_error, "cannot load pythonfmu's library %s (%s)", path, dlerror());
        return;
    }
#define RESOLVE(F) \
    if (!(p_##F = (F##TYPE *)dlsym(lib, #F))) { \
        snprintf(load_error, sizeof load_error, "%s lacks %s", path, #F); return; }
    FORWARDED(RESOLVE)
#undef RESOLVE
    *(void **)&p_finalizePythonInterpreter = dlsym(lib, "finalizePythonInterpreter");
    if (p_finalizePythonInterpreter) atexit(release_pythonfmu);
}

/* ------------------------------------------------------------------ logging */
static void own_logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                       fmi2String message, ...)
{
    Wrapper *w = (Wrapper *)env;
    if (!w) return;
    if ((int)status > w->worst) w->worst = (int)status;
    if (w->host.logger) w->host.logger(w->host.componentEnvironment, instance, status, category, message);
}

static void say(Wrapper *w, fmi2Status status, const char *fmt, ...)
{
    char esc[2400];
    va_list ap;
    va_start(ap, fmt);
    format_log_message(esc, sizeof esc, fmt, ap);
    va_end(ap);
    if (w && w->host.logger)
        w->host.logger(w->host.componentEnvironment, w->name, status,
                       status >= fmi2Error ? "logStatusError" : "logStatusWarning", esc);
}

/* the status to report: pythonfmu's, made fmi2Error when the call logged an error */
static fmi2Status outcome(Wrapper *w, fmi2Status s, const char *function)
{
    if (s == fmi2Fatal) {
        w->dead = 1;
        say(w, fmi2Error, "%s: the Python model failed; this instance cannot be used any more "
                          "(fmi2FreeInstance it)", function);
        return fmi2Error;
    }
    if (w->worst >= fmi2Error || s == fmi2Error || s == fmi2Discard) return fmi2Error;
    if (s == fmi2OK && w->worst == fmi2Warning) return fmi2Warning;
    return s;
}

static int usable(Wrapper *w, const char *function)
{
    if (!w) return 0;
    if (w->dead) {
        say(w, fmi2Error, "%s: this instance failed before and cannot be used any more", function);
        return 0;
    }
    w->worst = fmi2OK;
    return 1;
}

static int check_vrs(Wrapper *w, const fmi2ValueReference vr[], size_t nvr, const void *values, const char *kinds,
                     const char *function, const char *what)
{
    if (nvr > 0 && (!vr || !values)) { say(w, fmi2Error, "%s: null array", function); return 0; }
    for (size_t i = 0; i < nvr; ++i) {
        if (vr[i] >= LOADER_N_VARIABLES || !strchr(kinds, LOADER_VARIABLE_KIND[vr[i]])) {
            say(w, fmi2Error, "%s: %u is not the value reference of %s", function, vr[i], what);
            return 0;
        }
    }
    return 1;
}

/* ------------------------------------------------------------------ the API */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    if (!functions || !functions->logger) return NULL;
    const char *name = instanceName ? instanceName : LOADER_MODEL_IDENTIFIER;
    pthread_once(&once, bring_up);
    if (load_error[0]) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError", load_error);
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, LOADER_GUID) != 0) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "guid mismatch: the modelDescription.xml does not belong to this binary");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          LOADER_MODEL_IDENTIFIER " supports co-simulation only");
        return NULL;
    }
    Wrapper *w = (Wrapper *)calloc(1, sizeof(Wrapper));
    if (!w) return NULL;
    w->name = strdup(name);
    memcpy((void *)&w->host, functions, sizeof *functions);
    fmi2CallbackFunctions own = {own_logger, functions->allocateMemory ? functions->allocateMemory : calloc,
                                 functions->freeMemory ? functions->freeMemory : free, NULL, w};
    memcpy((void *)&w->own, &own, sizeof own);
    w->inner = p_fmi2Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation, &w->own, visible, loggingOn);
    if (!w->inner) {
        free(w->name);
        free(w);
        return NULL;
    }
    return w;
}

void fmi2FreeInstance(fmi2Component c)
{
    Wrapper *w = (Wrapper *)c;
    if (!w) return;
    if (!w->dead) p_fmi2FreeInstance(w->inner);
    free(w->name);
    free(w);
}

#define SIMPLE(F, ...) \
    Wrapper *w = (Wrapper *)c; \
    if (!usable(w, #F)) return fmi2Error; \
    return outcome(w, p_##F(w->inner, ##__VA_ARGS__), #F);

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[])
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2SetDebugLogging")) return fmi2Error;
    if (n > 0 && !categories) { say(w, fmi2Error, "fmi2SetDebugLogging: null array"); return fmi2Error; }
    return outcome(w, p_fmi2SetDebugLogging(w->inner, on, n, categories), "fmi2SetDebugLogging");
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDefined, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDefined, fmi2Real stop)
{ SIMPLE(fmi2SetupExperiment, tolDefined, tol, start, stopDefined, stop) }

fmi2Status fmi2EnterInitializationMode(fmi2Component c) { SIMPLE(fmi2EnterInitializationMode) }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { SIMPLE(fmi2ExitInitializationMode) }
fmi2Status fmi2Terminate(fmi2Component c) { SIMPLE(fmi2Terminate) }
fmi2Status fmi2Reset(fmi2Component c) { SIMPLE(fmi2Reset) }

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior)
{ SIMPLE(fmi2DoStep, t, h, noSetPrior) }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2GetReal")) return fmi2Error;
    if (!check_vrs(w, vr, nvr, value, "PIO", "fmi2GetReal", "a Real variable")) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return outcome(w, p_fmi2GetReal(w->inner, vr, nvr, value), "fmi2GetReal");
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2SetReal")) return fmi2Error;
    if (!check_vrs(w, vr, nvr, value, "PI", "fmi2SetReal", "an input or a Real parameter")) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return outcome(w, p_fmi2SetReal(w->inner, vr, nvr, value), "fmi2SetReal");
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2GetString")) return fmi2Error;
    if (!check_vrs(w, vr, nvr, value, "S", "fmi2GetString", "a String variable")) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return outcome(w, p_fmi2GetString(w->inner, vr, nvr, value), "fmi2GetString");
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2SetString")) return fmi2Error;
    if (!check_vrs(w, vr, nvr, value, "S", "fmi2SetString", "a String variable")) return fmi2Error;
    for (size_t i = 0; i < nvr; ++i)
        if (!value[i]) { say(w, fmi2Error, "fmi2SetString: null string"); return fmi2Error; }
    if (nvr == 0) return fmi2OK;
    return outcome(w, p_fmi2SetString(w->inner, vr, nvr, value), "fmi2SetString");
}

#define NO_VARIABLES(F, T, TYPE) \
fmi2Status F(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, TYPE value[]) \
{ \
    (void)vr; (void)value; \
    Wrapper *w = (Wrapper *)c; \
    if (!usable(w, #F)) return fmi2Error; \
    if (nvr == 0) return fmi2OK; \
    say(w, fmi2Error, #F ": this FMU has no " T " variables"); \
    return fmi2Error; \
}
NO_VARIABLES(fmi2GetInteger, "Integer", fmi2Integer)
NO_VARIABLES(fmi2SetInteger, "Integer", const fmi2Integer)
NO_VARIABLES(fmi2GetBoolean, "Boolean", fmi2Boolean)
NO_VARIABLES(fmi2SetBoolean, "Boolean", const fmi2Boolean)

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2GetFMUstate")) return fmi2Error;
    if (!state) { say(w, fmi2Error, "fmi2GetFMUstate: null pointer"); return fmi2Error; }
    return outcome(w, p_fmi2GetFMUstate(w->inner, state), "fmi2GetFMUstate");
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2SetFMUstate")) return fmi2Error;
    if (!state) { say(w, fmi2Error, "fmi2SetFMUstate: null state"); return fmi2Error; }
    return outcome(w, p_fmi2SetFMUstate(w->inner, state), "fmi2SetFMUstate");
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2FreeFMUstate")) return fmi2Error;
    if (!state) { say(w, fmi2Error, "fmi2FreeFMUstate: null pointer"); return fmi2Error; }
    if (!*state) return fmi2OK;
    return outcome(w, p_fmi2FreeFMUstate(w->inner, state), "fmi2FreeFMUstate");
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2SerializedFMUstateSize")) return fmi2Error;
    if (!state || !size) { say(w, fmi2Error, "fmi2SerializedFMUstateSize: null pointer"); return fmi2Error; }
    return outcome(w, p_fmi2SerializedFMUstateSize(w->inner, state, size), "fmi2SerializedFMUstateSize");
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2SerializeFMUstate")) return fmi2Error;
    if (!state || !bytes) { say(w, fmi2Error, "fmi2SerializeFMUstate: null pointer"); return fmi2Error; }
    size_t need = 0;
    if (p_fmi2SerializedFMUstateSize(w->inner, state, &need) != fmi2OK || need > size) {
        say(w, fmi2Error, "fmi2SerializeFMUstate: %u bytes given, %u needed", (unsigned)size, (unsigned)need);
        return fmi2Error;
    }
    return outcome(w, p_fmi2SerializeFMUstate(w->inner, state, bytes, need), "fmi2SerializeFMUstate");
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2DeSerializeFMUstate")) return fmi2Error;
    if (!bytes || !state) { say(w, fmi2Error, "fmi2DeSerializeFMUstate: null pointer"); return fmi2Error; }
    size_t magic = strlen(LOADER_STATE_MAGIC);
    if (size < magic || size > LOADER_STATE_MAX_BYTES || memcmp(bytes, LOADER_STATE_MAGIC, magic) != 0) {
        say(w, fmi2Error, "fmi2DeSerializeFMUstate: %u bytes that are not an FMU state written by this FMU",
            (unsigned)size);
        return fmi2Error;
    }
    return outcome(w, p_fmi2DeSerializeFMUstate(w->inner, bytes, size, state), "fmi2DeSerializeFMUstate");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference k[], size_t nk, const fmi2Real dk[], fmi2Real du[])
{
    (void)u; (void)nu; (void)k; (void)nk; (void)dk; (void)du;
    say((Wrapper *)c, fmi2Error, "directional derivatives are not provided");
    return fmi2Error;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    say((Wrapper *)c, fmi2Error, "input derivatives are not supported");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    say((Wrapper *)c, fmi2Error, "output derivatives are not provided");
    return fmi2Error;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    say((Wrapper *)c, fmi2Error, "fmi2CancelStep: steps are not asynchronous");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;   /* steps are synchronous: the status of the last one is what doStep returned */
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2GetStatus") || !value) return fmi2Error;
    *value = fmi2OK;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    Wrapper *w = (Wrapper *)c;
    if (!usable(w, "fmi2GetRealStatus") || !value) return fmi2Error;
    fmi2Status r = p_fmi2GetRealStatus(w->inner, s, value);
    return r == fmi2Discard ? fmi2Discard : outcome(w, r, "fmi2GetRealStatus");
}

