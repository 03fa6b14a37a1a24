/*
 * What the FMI API files (api/), the driver and the Python FMUs' loaders (python/) share: the
 * formatting of log messages, the phases' names, and -- in an FMI 2 binary -- the FMI 2.0
 * status queries that none of them supports (no asynchronous doStep, so no pending status to
 * report: they check their arguments and answer fmi2Discard; fmi2GetStatus and
 * fmi2GetRealStatus, which do answer, are in the API files).
 */
#include <stdio.h>

#include "fmu_common.h"

void format_log_message(char *out, size_t size, int double_percent, const char *fmt, va_list ap)
{
    char buf[1200];
    size_t j = 0;
    vsnprintf(buf, sizeof buf, fmt, ap);
    for (size_t i = 0; buf[i] && j + 2 < size; ++i) {
        if (double_percent && buf[i] == '%') out[j++] = '%';
        out[j++] = buf[i];
    }
    out[j] = '\0';
}

const char *phase_name(int phase)
{
    switch (phase) {
    case PhaseInstantiated: return "Instantiated";
    case PhaseInitializationMode: return "InitializationMode";
    case PhaseStepComplete: return "StepComplete";
    case PhaseTerminated: return "Terminated";
    case PhaseEventMode: return "EventMode";
    case PhaseContinuousTimeMode: return "ContinuousTimeMode";
    default: return "Error";
    }
}

const char *log_category(int status)
{
    return status == 1 ? "logStatusWarning" : status >= 3 ? "logStatusError" : "logAll";
}

#ifndef LCV_FMI3          /* the FMI 3.0 binary exports no fmi2 function */
#include "fmi2Functions.h"

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    if (!c || !value) return fmi2Error;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    (void)s;
    if (!c || !value) return fmi2Error;
    *value = fmi2False;
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    if (!c || !value) return fmi2Error;
    return fmi2Discard;
}
#endif
