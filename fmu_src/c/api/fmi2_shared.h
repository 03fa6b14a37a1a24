/* Shared by the C FMU and the pythonfmu loader; see fmi2_shared.c. */
#ifndef LCV_FMI2_SHARED_H
#define LCV_FMI2_SHARED_H

#include <stdarg.h>
#include <stddef.h>

#include "fmi2Functions.h"

/* printf-format into out (size bytes) with every '%' doubled: the finished text is passed
   to the host's logger as the message itself, so hosts that apply printf formatting print
   it as is and hosts that do not (Python hosts) get the text. */
void format_log_message(char *out, size_t size, const char *fmt, va_list ap);

/* the FMI log category of a status: logStatusWarning, logStatusError or logAll */
const char *log_category(fmi2Status status);

/* phases of the FMI 2.0 co-simulation state machine (bit masks, as Reference-FMUs): the C
   FMU's and the loader's (the loader enforces the same machine in front of pythonfmu) */
typedef enum {
    PhaseInstantiated = 1 << 0,
    PhaseInitializationMode = 1 << 1,
    PhaseStepComplete = 1 << 2,
    PhaseTerminated = 1 << 3,
    PhaseError = 1 << 4,
    PhaseEventMode = 1 << 5,              /* Model Exchange */
    PhaseContinuousTimeMode = 1 << 6      /* Model Exchange */
} Phase;
#define ANY_PHASE (PhaseInstantiated | PhaseInitializationMode | PhaseStepComplete | PhaseTerminated | PhaseError | \
                   PhaseEventMode | PhaseContinuousTimeMode)

/* the name of a phase, for messages */
const char *phase_name(int phase);

#endif
