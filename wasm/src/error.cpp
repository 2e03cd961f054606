#include "error.h"
#include <cstdio>

namespace gcs {
namespace {
GcsError g_code = GCS_OK;
char g_message[512] = "";
}  // namespace

bool fail(GcsError code, const char* format, ...) {
  g_code = code;
  va_list args;
  va_start(args, format);
  std::vsnprintf(g_message, sizeof g_message, format, args);
  va_end(args);
  return false;
}

void clearError() {
  g_code = GCS_OK;
  g_message[0] = '\0';
}

GcsError lastErrorCode() { return g_code; }
const char* lastErrorMessage() { return g_message; }

}  // namespace gcs
