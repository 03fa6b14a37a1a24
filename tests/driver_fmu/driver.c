/*
 * A small driver FMU for the closed-loop test: steer = -k_Y * Y1 - k_psi * psi1, a
 * lateral-position and heading feedback, no states (the output follows the inputs).
 * Value references: 0 k_Y [rad/m], 1 k_psi [rad/rad], 2 Y1 [m], 3 psi1 [rad], 4 delta [rad].
 * Built by tests/test_vehicle_fmus.py with the official FMI 2.0 headers from fmpy.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

typedef struct { double v[5]; } Driver;

static void update(Driver *d) { d->v[4] = -d->v[0] * d->v[2] - d->v[1] * d->v[3]; }

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[])
{ (void)c; (void)on; (void)n; (void)cat; return fmi2OK; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean log)
{
    (void)name; (void)res; (void)cb; (void)visible; (void)log;
    if (type != fmi2CoSimulation || !guid || strcmp(guid, "{5d1c0e1e-2b7a-4f7e-9d1e-d41e7e1d0001}")) return NULL;
    return calloc(1, sizeof(Driver));
}
void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean a, fmi2Real b, fmi2Real t, fmi2Boolean d, fmi2Real e)
{ (void)c; (void)a; (void)b; (void)t; (void)d; (void)e; return fmi2OK; }
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { update((Driver *)c); return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { memset(c, 0, sizeof(Driver)); return fmi2OK; }
fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[])
{
    Driver *d = (Driver *)c;
    update(d);
    for (size_t i = 0; i < n; ++i) { if (vr[i] > 4) return fmi2Error; v[i] = d->v[vr[i]]; }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[])
{
    Driver *d = (Driver *)c;
    for (size_t i = 0; i < n; ++i) { if (vr[i] > 3) return fmi2Error; d->v[vr[i]] = v[i]; }
    update(d);
    return fmi2OK;
}
#define NOVAR(F, T) fmi2Status F(fmi2Component c, const fmi2ValueReference vr[], size_t n, T v[]) \
    { (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
NOVAR(fmi2GetInteger, fmi2Integer) NOVAR(fmi2SetInteger, const fmi2Integer) NOVAR(fmi2GetBoolean, fmi2Boolean)
NOVAR(fmi2SetBoolean, const fmi2Boolean) NOVAR(fmi2GetString, fmi2String) NOVAR(fmi2SetString, const fmi2String)
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean b)
{ (void)t; (void)h; (void)b; update((Driver *)c); return fmi2OK; }
fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) { (void)c; (void)s; (void)n; return fmi2Error; }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n)
{ (void)c; (void)s; (void)b; (void)n; return fmi2Error; }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s)
{ (void)c; (void)b; (void)n; (void)s; return fmi2Error; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference a[], size_t b,
                                        const fmi2ValueReference d[], size_t e, const fmi2Real f[], fmi2Real g[])
{ (void)c; (void)a; (void)b; (void)d; (void)e; (void)f; (void)g; return fmi2Error; }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference a[], size_t b, const fmi2Integer d[],
                                       const fmi2Real e[])
{ (void)c; (void)a; (void)b; (void)d; (void)e; return fmi2Error; }
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference a[], size_t b, const fmi2Integer d[],
                                        fmi2Real e[])
{ (void)c; (void)a; (void)b; (void)d; (void)e; return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) { (void)c; (void)s; *v = fmi2OK; return fmi2OK; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) { (void)c; (void)s; (void)v; return fmi2Discard; }
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) { (void)c; (void)s; (void)v; return fmi2Discard; }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) { (void)c; (void)s; (void)v; return fmi2Discard; }
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) { (void)c; (void)s; (void)v; return fmi2Discard; }
