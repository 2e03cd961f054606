// Error recording shared by the whole core: one last-error slot (the core is single-threaded),
// set by whoever rejects an input, read by the C API.
#pragma once
#include <cstdarg>
#include "../include/gcs_skin.h"

namespace gcs {

// Records `code` and a printf-formatted sentence; always returns false so callers can
// `return fail(...)`.
bool fail(GcsError code, const char* format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void clearError();
GcsError lastErrorCode();
const char* lastErrorMessage();

}  // namespace gcs
