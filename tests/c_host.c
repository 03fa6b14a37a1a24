/*
 * A minimal FMI 2.0 co-simulation host in C99: dlopen, instantiate, step, get, and the
 * hostile calls of the test suite.  No Python in the process (unless the FMU brings it).
 * Its own declarations (not the official headers): an importer nobody else wrote.
 *
 *   c_host DIR IDENTIFIER GUID script      commands from stdin, one per line:
 *       S <vr> <text>      fmi2SetString
 *       s <vr> <value>     fmi2SetReal (value parsed by strtod: nan, inf, 1e308 ...)
 *       i                  fmi2ExitInitializationMode (EnterInitializationMode is done at start)
 *       d <t> <h>          fmi2DoStep
 *       g <vr> [<vr>...]   fmi2GetReal; prints "values <status> v1 v2 ..." with %.17g
 *       r                  fmi2Reset, fmi2SetupExperiment, fmi2EnterInitializationMode
 *       G / P / F          fmi2GetFMUstate / fmi2SetFMUstate / fmi2FreeFMUstate of one slot
 *       B                  serialize the slot, then deserialize the bytes into the slot
 *       N <offset>         serialize the slot, write a NaN at byte <offset>, deserialize
 *       K <offset> <int>   serialize the slot, write the int at byte <offset>, deserialize
 *       L <n>              <n> times fmi2GetFMUstate into the same slot
 *       t                  fmi2Terminate
 *       D <0|1>            fmi2SetDebugLogging(on/off, no categories)
 *       Z <n>              deserialize <n> bytes of garbage (0: empty)
 *       0                  deserialize from a NULL buffer
 *       c <n>              <n> cycles of instantiate, initialize, 10 steps, free
 *       m                  print "rss_kb <resident set size>"
 *   every call prints "status <n>"; log messages print as "log <status> <category> <message>".
 *   c_host DIR IDENTIFIER GUID bench <n_steps> <h> <vr_in> <vr_out>
 *       n steps of h with input vr_in = 1000; prints "us_per_step <x>" and output vr_out.
 *
 * DIR is the unzipped FMU; the library is DIR/binaries/linux64/IDENTIFIER.so.
 * Environment: LCV_HOST_URI replaces the resource location (file://DIR/resources; "NULL" for
 * a null pointer), LCV_HOST_NAME the instance name ("NULL" likewise), LCV_HOST_LOGGING=0
 * instantiates with loggingOn = false.
 * Build: gcc -std=c99 -O2 -o c_host c_host.c -ldl
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef int fmi2Status;
typedef char fmi2Byte;
typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*Instantiate_t)(fmi2String, int, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                       fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*Setup_t)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*Comp_t)(fmi2Component);
typedef void (*Free_t)(fmi2Component);
typedef fmi2Status (*SetReal_t)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*GetReal_t)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*SetString_t)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2String *);
typedef fmi2Status (*DoStep_t)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status (*GetState_t)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*SetState_t)(fmi2Component, fmi2FMUstate);
typedef fmi2Status (*StateSize_t)(fmi2Component, fmi2FMUstate, size_t *);
typedef fmi2Status (*Serialize_t)(fmi2Component, fmi2FMUstate, fmi2Byte *, size_t);
typedef fmi2Status (*Deserialize_t)(fmi2Component, const fmi2Byte *, size_t, fmi2FMUstate *);

static int quiet = 0;

static void logger(fmi2ComponentEnvironment env, fmi2String inst, fmi2Status st, fmi2String cat, fmi2String msg, ...)
{
    (void)env; (void)inst;
    char buf[4096];
    va_list ap;
    if (quiet) return;
    va_start(ap, msg);
    vsnprintf(buf, sizeof buf, msg ? msg : "", ap);
    va_end(ap);
    for (char *p = buf; *p; ++p) if (*p == '\n') *p = ' ';
    printf("log %d %s %s\n", st, cat ? cat : "", buf);
    fflush(stdout);
}

static void *sym(void *lib, const char *name)
{
    void *f = dlsym(lib, name);
    if (!f) { fprintf(stderr, "missing symbol %s\n", name); exit(3); }
    return f;
}

static long rss_kb(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f) return -1;
    if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = -1;
    fclose(f);
    return resident * 4;
}

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: c_host DIR IDENTIFIER GUID script | bench n h vr_in vr_out\n");
        return 2;
    }
    const char *dir = argv[1], *id = argv[2], *guid = argv[3], *mode = argv[4];
    char path[4096], uri[4096];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, id);
    snprintf(uri, sizeof uri, "file://%s/resources", dir);
    const char *uri_arg = uri, *name_arg = "host";
    if (getenv("LCV_HOST_URI")) uri_arg = strcmp(getenv("LCV_HOST_URI"), "NULL") == 0 ? NULL : getenv("LCV_HOST_URI");
    if (getenv("LCV_HOST_NAME")) name_arg = strcmp(getenv("LCV_HOST_NAME"), "NULL") == 0 ? NULL : getenv("LCV_HOST_NAME");
    int logging = !(getenv("LCV_HOST_LOGGING") && strcmp(getenv("LCV_HOST_LOGGING"), "0") == 0);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen failed: %s\n", dlerror()); return 3; }

    Instantiate_t instantiate = (Instantiate_t)sym(lib, "fmi2Instantiate");
    Setup_t setup = (Setup_t)sym(lib, "fmi2SetupExperiment");
    Comp_t enter = (Comp_t)sym(lib, "fmi2EnterInitializationMode");
    Comp_t exitinit = (Comp_t)sym(lib, "fmi2ExitInitializationMode");
    Comp_t terminate = (Comp_t)sym(lib, "fmi2Terminate");
    Comp_t reset = (Comp_t)sym(lib, "fmi2Reset");
    Free_t freeinst = (Free_t)sym(lib, "fmi2FreeInstance");
    SetReal_t setReal = (SetReal_t)sym(lib, "fmi2SetReal");
    GetReal_t getReal = (GetReal_t)sym(lib, "fmi2GetReal");
    SetString_t setString = (SetString_t)sym(lib, "fmi2SetString");
    DoStep_t doStep = (DoStep_t)sym(lib, "fmi2DoStep");
    GetState_t getState = (GetState_t)sym(lib, "fmi2GetFMUstate");
    SetState_t setState = (SetState_t)sym(lib, "fmi2SetFMUstate");
    GetState_t freeState = (GetState_t)sym(lib, "fmi2FreeFMUstate");
    typedef fmi2Status (*Debug_t)(fmi2Component, fmi2Boolean, size_t, const fmi2String *);
    Debug_t debugLogging = (Debug_t)sym(lib, "fmi2SetDebugLogging");
    StateSize_t stateSize = (StateSize_t)sym(lib, "fmi2SerializedFMUstateSize");
    Serialize_t serialize = (Serialize_t)sym(lib, "fmi2SerializeFMUstate");
    Deserialize_t deserialize = (Deserialize_t)sym(lib, "fmi2DeSerializeFMUstate");

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate(name_arg, 1 /* fmi2CoSimulation */, guid, uri_arg, &cb, 0, logging);
    if (!c) { printf("instantiate failed\n"); fflush(stdout); return 4; }
    setup(c, 0, 0.0, 0.0, 0, 0.0);
    enter(c);

    if (strcmp(mode, "bench") == 0) {
        if (argc < 9) { fprintf(stderr, "bench needs: n h vr_in vr_out\n"); return 2; }
        long n = atol(argv[5]);
        double h = atof(argv[6]);
        exitinit(c);
        struct timespec t0, t1;
        double t = 0.0, y = 0.0, p = 1000.0;
        fmi2ValueReference in_vr = (fmi2ValueReference)atol(argv[7]), out_vr = (fmi2ValueReference)atol(argv[8]);
        setReal(c, &in_vr, 1, &p);
        clock_gettime(CLOCK_MONOTONIC, &t0);
        for (long k = 0; k < n; ++k) {
            if (doStep(c, t, h, 1) != 0) { fprintf(stderr, "doStep failed at %ld\n", k); return 5; }
            t += h;
        }
        clock_gettime(CLOCK_MONOTONIC, &t1);
        getReal(c, &out_vr, 1, &y);
        double us = ((t1.tv_sec - t0.tv_sec) * 1e6 + (t1.tv_nsec - t0.tv_nsec) / 1e3) / (double)n;
        printf("us_per_step %.6f\noutput %.17g\n", us, y);
    } else {
        char line[8192];
        fmi2FMUstate slot = NULL;
        while (fgets(line, sizeof line, stdin)) {
            char *p = line;
            char cmd = *p++;
            if (cmd == 'S') {
                unsigned vr; char text[4096] = "";
                if (sscanf(p, "%u %4095s", &vr, text) < 1) continue;
                fmi2String s = text;
                fmi2ValueReference v = vr;
                printf("status %d\n", setString(c, &v, 1, &s));
            } else if (cmd == 's') {
                unsigned vr; char num[128];
                if (sscanf(p, "%u %127s", &vr, num) != 2) continue;
                double x = strtod(num, NULL);
                fmi2ValueReference v = vr;
                printf("status %d\n", setReal(c, &v, 1, &x));
            } else if (cmd == 'i') {
                printf("status %d\n", exitinit(c));
            } else if (cmd == 'd') {
                char a[128], b[128];
                if (sscanf(p, "%127s %127s", a, b) != 2) continue;
                printf("status %d\n", doStep(c, strtod(a, NULL), strtod(b, NULL), 1));
            } else if (cmd == 'g') {
                fmi2ValueReference vrs[512]; double vals[512]; size_t n = 0; int off = 0; unsigned v;
                while (n < 512 && sscanf(p, "%u%n", &v, &off) == 1) { vrs[n++] = v; p += off; }
                fmi2Status st = getReal(c, vrs, n, vals);
                printf("values %d", st);
                for (size_t k = 0; k < n; ++k) printf(" %.17g", vals[k]);
                printf("\n");
            } else if (cmd == 'r') {
                printf("status %d\n", reset(c));
                setup(c, 0, 0.0, 0.0, 0, 0.0);
                enter(c);
            } else if (cmd == 'G') {
                printf("status %d\n", getState(c, &slot));
            } else if (cmd == 'P') {
                printf("status %d\n", setState(c, slot));
            } else if (cmd == 'F') {
                printf("status %d\n", freeState(c, &slot));
            } else if (cmd == 't') {
                printf("status %d\n", terminate(c));
            } else if (cmd == 'D') {
                printf("status %d\n", debugLogging(c, atoi(p) != 0, 0, NULL));
            } else if (cmd == 'L') {
                long n = atol(p);
                fmi2Status st = 0;
                for (long k = 0; k < n && st == 0; ++k) st = getState(c, &slot);
                printf("status %d\n", st);
            } else if (cmd == 'B' || cmd == 'N' || cmd == 'K') {
                size_t size = 0;
                int offset = -1, number = 0;
                if (cmd != 'B' && sscanf(p, "%d %d", &offset, &number) < 1) continue;
                if (stateSize(c, slot, &size) != 0 || size == 0) { printf("status 3\n"); continue; }
                fmi2Byte *buf = (fmi2Byte *)malloc(size);
                fmi2Status st = serialize(c, slot, buf, size);
                if (cmd == 'N' && offset >= 0 && (size_t)offset + sizeof(double) <= size) {
                    double nan = NAN;
                    memcpy(buf + offset, &nan, sizeof nan);
                }
                if (cmd == 'K' && offset >= 0 && (size_t)offset + sizeof(int) <= size)
                    memcpy(buf + offset, &number, sizeof number);
                if (st == 0) st = deserialize(c, buf, size, &slot);
                printf("status %d\n", st);
                free(buf);
            } else if (cmd == 'Z') {
                size_t n = (size_t)atol(p);
                fmi2Byte *buf = (fmi2Byte *)malloc(n + 1);
                for (size_t k = 0; k < n; ++k) buf[k] = (fmi2Byte)(37 * k + 11);
                fmi2FMUstate tmp = NULL;
                fmi2Status st = deserialize(c, buf, n, &tmp);
                printf("status %d\n", st);
                if (tmp) freeState(c, &tmp);
                free(buf);
            } else if (cmd == '0') {
                fmi2FMUstate tmp = NULL;
                printf("status %d\n", deserialize(c, NULL, 100, &tmp));
            } else if (cmd == 'c') {
                long n = atol(p);
                quiet = 1;
                for (long k = 0; k < n; ++k) {
                    fmi2Component d = instantiate("cycle", 1, guid, uri, &cb, 0, 0);
                    if (!d) { quiet = 0; printf("cycle instantiate failed\n"); break; }
                    setup(d, 0, 0.0, 0.0, 0, 0.0);
                    enter(d);
                    exitinit(d);
                    for (int j = 0; j < 10; ++j) doStep(d, j * 0.01, 0.01, 1);
                    terminate(d);
                    freeinst(d);
                }
                quiet = 0;
                printf("cycles %ld\n", n);
            } else if (cmd == 'm') {
                printf("rss_kb %ld\n", rss_kb());
            }
            fflush(stdout);
        }
        if (slot) freeState(c, &slot);
    }
    terminate(c);
    freeinst(c);
    dlclose(lib);
    printf("done\n");
    fflush(stdout);
    return 0;
}
