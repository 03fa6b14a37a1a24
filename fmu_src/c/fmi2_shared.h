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

#endif
