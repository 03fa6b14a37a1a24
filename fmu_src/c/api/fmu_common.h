/* What every FMI API file of this tree shares, FMI-neutral (no FMI type): the API files over
   any model (api/), the driver, and the Python FMUs' loaders (python/); see fmu_common.c. */
#ifndef LCV_FMU_COMMON_H
#define LCV_FMU_COMMON_H

#include <stdarg.h>
#include <stddef.h>

/* printf-format into out (size bytes); with double_percent, every '%' doubled: an FMI 2.0
   logger's message is itself a printf format (the host formats it, so a literal '%' must be
   "%%"), an FMI 3.0 logMessage's is plain text (no doubling: "[-20, 20] %" stays one '%'). */
void format_log_message(char *out, size_t size, int double_percent, const char *fmt, va_list ap);

/* the FMI log category of a status (FMI 2 and 3 number them alike: 0 OK, 1 Warning, 2 Discard,
   3 Error, 4 Fatal): logStatusWarning, logStatusError or logAll */
const char *log_category(int status);

/* phases of the FMI state machine (bit masks, as Reference-FMUs): the C FMU's and the loaders'
   (which enforce the same machine in front of pythonfmu and pythonfmu3) */
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
