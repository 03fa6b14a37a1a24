/*
 * A minimal FMI 2.0 co-simulation host in C99: dlopen, instantiate, step, get.
 * No Python anywhere in the process (unless the FMU itself needs it).
 *
 *   c_host DIR IDENTIFIER GUID script      commands from stdin, one per line:
 *       S <vr> <text>      fmi2SetString (before "i")
 *       s <vr> <value>     fmi2SetReal
 *       i                  fmi2ExitInitializationMode (fmi2EnterInitializationMode is done at start)
 *       d <t> <h>          fmi2DoStep; prints "status <n>"
 *       g <vr> [<vr>...]   fmi2GetReal; prints "values v1 v2 ..." with %.17g
 *       r                  fmi2Reset then fmi2SetupExperiment and fmi2EnterInitializationMode
 *   c_host DIR IDENTIFIER GUID bench <n_steps> <h> <vr_in> <vr_out>
 *       default parameters, input vr_in = 1000 (P61 in N), n steps of h; prints
 *       "us_per_step <x>" and the output vr_out (y6); the caller reads the value
 *       references from modelDescription.xml
 *
 * DIR is the unzipped FMU; the library is DIR/binaries/linux64/IDENTIFIER.so.
 * Log messages from the FMU are printed as "log <status> <category> <message>".
 * Build: gcc -std=c99 -O2 -o c_host c_host.c -ldl
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef int fmi2Status;
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

static void logger(fmi2ComponentEnvironment env, fmi2String inst, fmi2Status st, fmi2String cat, fmi2String msg, ...)
{
    (void)env; (void)inst;
    char buf[2048];
    va_list ap;
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

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("host", 1 /* fmi2CoSimulation */, guid, uri, &cb, 0, 1);
    if (!c) { fprintf(stderr, "instantiate failed\n"); return 4; }
    setup(c, 0, 0.0, 0.0, 0, 0.0);
    enter(c);

    if (strcmp(mode, "bench") == 0) {
        long n = argc > 5 ? atol(argv[5]) : 1000000;
        double h = argc > 6 ? atof(argv[6]) : 1e-3;
        exitinit(c);
        if (argc < 9) { fprintf(stderr, "bench needs: n h vr_in vr_out\n"); return 2; }
        struct timespec t0, t1;
        double t = 0.0, y = 0.0;
        fmi2ValueReference in_vr = (fmi2ValueReference)atol(argv[7]);
        fmi2ValueReference out_vr = (fmi2ValueReference)atol(argv[8]);
        double p61 = 1000.0;
        setReal(c, &in_vr, 1, &p61);
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
                fmi2ValueReference vrs[256]; double vals[256]; size_t n = 0; int off = 0; unsigned v;
                while (n < 256 && sscanf(p, "%u%n", &v, &off) == 1) { vrs[n++] = v; p += off; }
                fmi2Status st = getReal(c, vrs, n, vals);
                printf("values %d", st);
                for (size_t k = 0; k < n; ++k) printf(" %.17g", vals[k]);
                printf("\n");
            } else if (cmd == 'r') {
                printf("status %d\n", reset(c));
                setup(c, 0, 0.0, 0.0, 0, 0.0);
                enter(c);
            }
            fflush(stdout);
        }
    }
    terminate(c);
    freeinst(c);
    dlclose(lib);
    printf("done\n");
    return 0;
}
