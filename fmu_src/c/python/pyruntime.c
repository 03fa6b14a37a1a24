/*
 * The Python runtime of the Python FMUs' loaders (loader.c: FMI 2.0 in front of pythonfmu;
 * loader3.c: FMI 3.0 in front of pythonfmu3): find or start the Python the FMU was built
 * with, add the recorded site-packages, import numpy, load the export library next to the
 * loader, and take the resources folder off sys.path when the last instance is freed.
 * loader.c's header comment says why each step is done the way it is.
 */
#include <Python.h>     /* first (it sets the feature macros); types only (PyConfig, PyStatus): every
                           Python function is looked up with dlsym, nothing links to libpython */
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <wchar.h>

#include "loader_config.h"
#include "pyruntime.h"

static pthread_once_t once = PTHREAD_ONCE_INIT;
static char load_error[2048];
static char export_path[4096];
static void *export_lib = NULL;
static void (*p_finalizePythonInterpreter)(void);

/* pythonfmu (0.7.0, and pythonfmu3 0.3.4 the same) keeps its interpreter state in a static
   std::shared_ptr, destroyed by a C++ static destructor at exit; its library destructor
   (finalizePythonInterpreter) then assigns to the destroyed pointer -- a use after free
   (valgrind: "Invalid read ... in finalizePythonInterpreter ... block free'd in
   __run_exit_handlers") that corrupts the heap and aborts the host at exit ("free(): corrupted
   unsorted chunks").  Releasing the state before the static destructors run (atexit handlers
   run in reverse order of registration, and this one is registered after pythonfmu's) leaves
   nothing to free twice. */
static void release_pythonfmu(void)
{
    if (p_finalizePythonInterpreter) p_finalizePythonInterpreter();
}

static const char *setting(const char *env, const char *recorded)
{
    const char *v = getenv(env);
    return v && *v ? v : recorded;
}

int pyrt_is_dir(const char *path)
{
    struct stat st;
    return path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

int pyrt_is_file(const char *path)
{
    struct stat st;
    return path && stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* the Python home to start with, or "" for Python's own default; 0 and load_error if unusable */
static int python_home(const char *libpython, char *home, size_t size)
{
    const char *env_home = getenv("LCV_FMU_PYTHONHOME");
    const char *env_lib = getenv("LCV_FMU_LIBPYTHON");
    char landmark[4200];
    home[0] = '\0';
    if (env_home && *env_home) {
        snprintf(home, size, "%s", env_home);
    } else if (env_lib && *env_lib) {
        /* <prefix>/lib/libpythonX.Y.so or <prefix>/lib/<multiarch>/libpythonX.Y.so */
        char prefix[4096];
        snprintf(prefix, sizeof prefix, "%s", libpython);
        for (int up = 0; up < 3; ++up) {
            char *slash = strrchr(prefix, '/');
            if (!slash || slash == prefix) break;
            *slash = '\0';
            snprintf(landmark, sizeof landmark, "%s/lib/python%s/os.py", prefix, LOADER_PYTHON_VERSION);
            if (up > 0 && pyrt_is_file(landmark)) { snprintf(home, size, "%s", prefix); break; }
        }
        return 1;                 /* not found: Python's compiled-in prefix */
    } else {
        snprintf(home, size, "%s", LOADER_PYTHON_HOME);
    }
    snprintf(landmark, sizeof landmark, "%s/lib/python%s/os.py", home, LOADER_PYTHON_VERSION);
    if (!pyrt_is_file(landmark)) {
        snprintf(load_error, sizeof load_error,
                 "the Python home %.900s has no standard library (%.900s is missing); set LCV_FMU_PYTHONHOME to the "
                 "prefix of the Python %s whose library LCV_FMU_LIBPYTHON names (or unset it)",
                 home, landmark, LOADER_PYTHON_VERSION);
        return 0;
    }
    return 1;
}

typedef int (*int_void_t)(void);
typedef const char *(*str_void_t)(void);
typedef void *(*ptr_void_t)(void);
typedef int (*gil_ensure_t)(void);
typedef void (*gil_release_t)(int);
typedef int (*run_t)(const char *);
typedef void (*preinit_config_t)(PyPreConfig *);
typedef PyStatus (*preinit_t)(const PyPreConfig *);
typedef void (*config_init_t)(PyConfig *);
typedef PyStatus (*config_set_t)(PyConfig *, wchar_t **, const char *);
typedef PyStatus (*init_t)(const PyConfig *);
typedef void (*config_clear_t)(PyConfig *);
typedef int (*status_exception_t)(PyStatus);

/* run Python code with the GIL held; returns PyRun_SimpleString's result */
/* Run ``code`` in a namespace of its own: PyRun_SimpleString runs in the host's __main__, so
 * the code travels as hex inside one exec() that binds nothing there.  ``arg`` (may be NULL)
 * is given to the code as the str ``arg``, also as hex (paths are never pasted into code). */
static int run_python_arg(void *py, const char *code, const char *arg)
{
    gil_ensure_t ensure = (gil_ensure_t)dlsym(py, "PyGILState_Ensure");
    gil_release_t release = (gil_release_t)dlsym(py, "PyGILState_Release");
    run_t run = (run_t)dlsym(py, "PyRun_SimpleString");
    if (!ensure || !release || !run) return -1;
    size_t nc = strlen(code), na = arg ? strlen(arg) : 0;
    char *wrapped = (char *)malloc(2 * (nc + na) + 256);
    if (!wrapped) return -1;
    int k = sprintf(wrapped, "exec(bytes.fromhex('");
    for (size_t i = 0; i < nc; ++i) k += sprintf(wrapped + k, "%02x", (unsigned char)code[i]);
    k += sprintf(wrapped + k, "').decode(), {'__name__': '__lcv_fmu_loader__', 'arg': bytes.fromhex('");
    for (size_t i = 0; i < na; ++i) k += sprintf(wrapped + k, "%02x", (unsigned char)arg[i]);
    sprintf(wrapped + k, "').decode('utf-8', 'surrogateescape')})\n");
    int g = ensure();
    int r = run(wrapped);
    release(g);
    free(wrapped);
    return r;
}

static int run_python(void *py, const char *code) { return run_python_arg(py, code, NULL); }

static int status_failed(void *py, PyStatus st, const char *what)
{
    status_exception_t failed = (status_exception_t)dlsym(py, "PyStatus_Exception");
    if (!failed || !failed(st)) return 0;
    snprintf(load_error, sizeof load_error, "the Python interpreter could not be started (%s: %s%s%s); check "
             "LCV_FMU_LIBPYTHON and LCV_FMU_PYTHONHOME", what, st.func ? st.func : "", st.func ? ": " : "",
             st.err_msg ? st.err_msg : (st.exitcode ? "exit requested" : "unknown error"));
    return 1;
}

static int start_python(void *py, const char *libpython)
{
    char home[4096];
    if (!python_home(libpython, home, sizeof home)) return 0;
    preinit_config_t pre_init = (preinit_config_t)dlsym(py, "PyPreConfig_InitIsolatedConfig");
    preinit_t pre = (preinit_t)dlsym(py, "Py_PreInitialize");
    config_init_t config_init = (config_init_t)dlsym(py, "PyConfig_InitIsolatedConfig");
    config_set_t set_string = (config_set_t)dlsym(py, "PyConfig_SetBytesString");
    init_t init = (init_t)dlsym(py, "Py_InitializeFromConfig");
    config_clear_t clear = (config_clear_t)dlsym(py, "PyConfig_Clear");
    ptr_void_t save = (ptr_void_t)dlsym(py, "PyEval_SaveThread");
    if (!pre_init || !pre || !config_init || !set_string || !init || !clear || !save) {
        snprintf(load_error, sizeof load_error, "%.1800s lacks the Python initialization API", libpython);
        return 0;
    }
    PyPreConfig preconfig;
    pre_init(&preconfig);
    preconfig.utf8_mode = 1;          /* paths are UTF-8 whatever the host's locale */
    preconfig.configure_locale = 0;   /* the host's locale is the host's */
    if (status_failed(py, pre(&preconfig), "pre-initialization")) return 0;
    PyConfig config;
    config_init(&config);
    config.install_signal_handlers = 0;     /* leave the host's signal handlers alone */
    config.site_import = 1;
    if (home[0] && status_failed(py, set_string(&config, &config.home, home), "home")) {
        clear(&config);
        return 0;
    }
    PyStatus st = init(&config);
    clear(&config);
    if (status_failed(py, st, "initialization")) return 0;
    (void)save();                 /* release the GIL; pythonfmu takes it per call */
    return 1;
}

/* The recorded site-packages (numpy).  In the FMU's own interpreter: site.addsitedir.  In a
 * Python host's: nothing if the host has numpy; else the folder on sys.path only while numpy
 * is imported (no .pth files run, no finder installed, sys.path as the host had it). */
static int add_site_dir(void *py, const char *site, int own_interpreter)
{
    return run_python_arg(py, own_interpreter ?
        "import sys, site\nif arg not in sys.path: site.addsitedir(arg)\n" :
        "import sys, importlib.util\n"
        "if importlib.util.find_spec('numpy') is None:\n"
        "    sys.path.append(arg)\n"
        "    try:\n"
        "        import numpy\n"
        "    finally:\n"
        "        sys.path.remove(arg)\n", site);
}

/* pythonfmu puts the resources folder on sys.path and leaves it there: take it away when the
 * last instance of this FMU is freed (the modules it imported stay imported, as any import) */
static pthread_mutex_t live_lock = PTHREAD_MUTEX_INITIALIZER;
static int live_instances = 0;
static void *python_lib = NULL;           /* RTLD_DEFAULT (NULL) in a Python host */
static int python_ready = 0;

static void forget_resources(const char *folder)
{
    if (!python_ready) return;
    (void)run_python_arg(python_lib,
        "import os, sys\n"
        "mine = os.path.realpath(arg)\n"
        "sys.path[:] = [p for p in sys.path if not (isinstance(p, str) and p and os.path.realpath(p) == mine)]\n",
        folder);
}

/* remove every sys.path entry equal to ``path`` (as text: an alias whose link is about to go) */
static void forget_path(const char *path)
{
    if (!python_ready) return;
    (void)run_python_arg(python_lib, "import sys\nsys.path[:] = [p for p in sys.path if p != arg]\n", path);
}

static void bring_up(void)
{
    const char *libpython = setting("LCV_FMU_LIBPYTHON", LOADER_LIBPYTHON);
    const char *site = setting("LCV_FMU_SITE_PACKAGES", LOADER_SITE_PACKAGES);
    void *py = RTLD_DEFAULT;
    int_void_t is_init = (int_void_t)dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    int started = 0;
    if (!is_init) {
        py = dlopen(libpython, RTLD_NOW | RTLD_GLOBAL);
        if (!py) {
            snprintf(load_error, sizeof load_error,
                     "cannot load the Python library %.800s recorded when this FMU was built (%s); set "
                     "LCV_FMU_LIBPYTHON to the libpython%s of a Python environment that has numpy, and "
                     "LCV_FMU_SITE_PACKAGES to its site-packages", libpython, dlerror(), LOADER_PYTHON_VERSION);
            return;
        }
        is_init = (int_void_t)dlsym(py, "Py_IsInitialized");
    }
    str_void_t version = (str_void_t)dlsym(py, "Py_GetVersion");
    if (!is_init || !version) {
        snprintf(load_error, sizeof load_error, "%.1800s is not a Python library (set LCV_FMU_LIBPYTHON)", libpython);
        return;
    }
    if (strncmp(version(), LOADER_PYTHON_VERSION ".", strlen(LOADER_PYTHON_VERSION) + 1) != 0) {
        snprintf(load_error, sizeof load_error, "this process runs Python %.20s; the FMU was built for Python %s",
                 version(), LOADER_PYTHON_VERSION);
        return;
    }
    if (!is_init()) {
        if (!start_python(py, libpython)) return;
        started = 1;
    }
    if (site && *site) {
        if (!pyrt_is_dir(site)) {
            snprintf(load_error, sizeof load_error, "the site-packages folder %.1200s does not exist; set "
                     "LCV_FMU_SITE_PACKAGES to the site-packages of a Python %s environment that has numpy",
                     site, LOADER_PYTHON_VERSION);
            return;
        }
        if (add_site_dir(py, site, started) != 0) {
            snprintf(load_error, sizeof load_error, "cannot add %.1200s to the Python path", site);
            return;
        }
    }
    python_lib = py;
    python_ready = 1;
    /* the FMU's own interpreter runs BLAS with one thread (LCV_BLAS_THREADS, or the standard variables where
       the host set them): OpenBLAS reads the environment when numpy loads it; the variables the FMU set are
       taken away again, so the host's environment is as it was.  A Python host's numpy is the host's. */
    if (run_python(py, started ?
                   "import os\n"
                   "names = ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS')\n"
                   "added = [v for v in names if v not in os.environ]\n"
                   "n = os.environ.get('LCV_BLAS_THREADS', '1').strip()\n"
                   "n = n if n.isdigit() and int(n) >= 1 else '1'\n"
                   "for v in added:\n"
                   "    os.environ[v] = n\n"
                   "try:\n"
                   "    import numpy\n"
                   "finally:\n"
                   "    for v in added:\n"
                   "        del os.environ[v]\n" : "import numpy\n") != 0) {
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
        snprintf(load_error, sizeof load_error, "cannot load pythonfmu's library %.1000s (%.800s)", path, dlerror());
        return;
    }
    snprintf(export_path, sizeof export_path, "%s", path);
    export_lib = lib;
    *(void **)&p_finalizePythonInterpreter = dlsym(lib, "finalizePythonInterpreter");
    if (p_finalizePythonInterpreter) atexit(release_pythonfmu);
}

void *pyrt_start(const char **error, const char **path)
{
    pthread_once(&once, bring_up);
    *error = load_error[0] ? load_error : NULL;
    *path = export_path;
    return load_error[0] ? NULL : export_lib;
}

void pyrt_instance_added(void)
{
    pthread_mutex_lock(&live_lock);
    ++live_instances;
    pthread_mutex_unlock(&live_lock);
}

void pyrt_instance_freed(const char *folder)
{
    pthread_mutex_lock(&live_lock);
    int last = --live_instances == 0;
    pthread_mutex_unlock(&live_lock);
    if (last && folder) forget_resources(folder);
}


/* ------------------------------------------------------------------ the resources' alias */
int pyrt_needs_alias(const char *folder)
{
    return strstr(folder, "%20") != NULL || strstr(folder, "file:/") != NULL;
}

int pyrt_resource_alias(const char *folder, char *alias, size_t size, char *why, size_t wsize)
{
    char dir[64];
    snprintf(dir, sizeof dir, "/tmp/lcv-fmu-XXXXXX");
    if (!mkdtemp(dir)) {
        snprintf(why, wsize, "the resource folder %.1000s has \"%%20\" or \"file:/\" in its path, which the Python "
                 "FMU's runtime rewrites, and no alias of it could be made under /tmp; unzip the FMU elsewhere", folder);
        return 0;
    }
    snprintf(alias, size, "%s/resources", dir);
    if (symlink(folder, alias) != 0) {
        rmdir(dir);
        snprintf(why, wsize, "the resource folder %.1000s has \"%%20\" or \"file:/\" in its path, and its alias "
                 "could not be made; unzip the FMU elsewhere", folder);
        return 0;
    }
    return 1;
}

void pyrt_resource_alias_free(const char *alias)
{
    if (!alias || !*alias) return;
    forget_path(alias);
    unlink(alias);
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", alias);
    char *slash = strrchr(dir, '/');
    if (slash) {
        *slash = '\0';
        rmdir(dir);
    }
}


/* ------------------------------------------------------------------ text */
int pyrt_valid_utf8(const unsigned char *s)
{
    while (*s) {
        int n = *s < 0x80 ? 0 : (*s & 0xE0) == 0xC0 ? 1 : (*s & 0xF0) == 0xE0 ? 2 : (*s & 0xF8) == 0xF0 ? 3 : -1;
        if (n < 0 || (n == 1 && *s < 0xC2)) return 0;
        ++s;
        for (int i = 0; i < n; ++i, ++s)
            if ((*s & 0xC0) != 0x80) return 0;
    }
    return 1;
}

/* the folder a file: URI names (RFC 8089: file:///p, file:/p, file://localhost/p, %XX
   escapes), checked to exist and to hold the slave module; 0 and a reason otherwise */
