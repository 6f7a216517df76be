#include "capi/api_support.h"

#include <mutex>
#include <unordered_set>

namespace drape::api {

namespace {

thread_local std::string t_lastError;

struct Registry {
  std::mutex mutex;
  std::unordered_set<const void*> live[2];
};

Registry& registry() {
  static Registry* r = new Registry();  // never destroyed: safe to use during static teardown
  return *r;
}

}  // namespace

drape_result fail(drape_result result, const std::string& message) {
  try {
    t_lastError = message;
  } catch (...) {
    // Could not allocate the message: keep the code, which is what callers act on.
  }
  return result;
}

void registerHandle(HandleKind kind, const void* handle) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.live[static_cast<int>(kind)].insert(handle);
}

void unregisterHandle(HandleKind kind, const void* handle) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.live[static_cast<int>(kind)].erase(handle);
}

bool isLiveHandle(HandleKind kind, const void* handle) {
  if (!handle) return false;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  return r.live[static_cast<int>(kind)].count(handle) != 0;
}

drape_result checkStructSize(uint32_t struct_size, size_t min_size, const char* what) {
  if (struct_size < min_size) {
    return fail(DRAPE_ERROR_INVALID_ARGUMENT,
                std::string(what) + ".struct_size is " + std::to_string(struct_size) +
                    ", expected at least " + std::to_string(min_size) +
                    " (initialise the struct with its _init function)");
  }
  return DRAPE_OK;
}

const char* lastError() { return t_lastError.c_str(); }

}  // namespace drape::api

extern "C" {

DRAPE_API const char* DRAPE_CALL drape_last_error(void) { return drape::api::lastError(); }

DRAPE_API const char* DRAPE_CALL drape_result_name(drape_result result) {
  switch (result) {
    case DRAPE_OK: return "DRAPE_OK";
    case DRAPE_ERROR_NULL_ARGUMENT: return "DRAPE_ERROR_NULL_ARGUMENT";
    case DRAPE_ERROR_INVALID_ARGUMENT: return "DRAPE_ERROR_INVALID_ARGUMENT";
    case DRAPE_ERROR_INVALID_HANDLE: return "DRAPE_ERROR_INVALID_HANDLE";
    case DRAPE_ERROR_BUFFER_TOO_SMALL: return "DRAPE_ERROR_BUFFER_TOO_SMALL";
    case DRAPE_ERROR_NONFINITE: return "DRAPE_ERROR_NONFINITE";
    case DRAPE_ERROR_OUT_OF_RANGE: return "DRAPE_ERROR_OUT_OF_RANGE";
    case DRAPE_ERROR_CALL_ORDER: return "DRAPE_ERROR_CALL_ORDER";
    case DRAPE_ERROR_TIMESTAMP: return "DRAPE_ERROR_TIMESTAMP";
    case DRAPE_ERROR_IO: return "DRAPE_ERROR_IO";
    case DRAPE_ERROR_PARSE: return "DRAPE_ERROR_PARSE";
    case DRAPE_ERROR_OUT_OF_MEMORY: return "DRAPE_ERROR_OUT_OF_MEMORY";
    case DRAPE_ERROR_INTERNAL: return "DRAPE_ERROR_INTERNAL";
    default: return "DRAPE_ERROR_UNKNOWN";
  }
}

DRAPE_API uint32_t DRAPE_CALL drape_version(void) { return DRAPE_VERSION; }

DRAPE_API const char* DRAPE_CALL drape_version_string(void) {
#define DRAPE_STR2(x) #x
#define DRAPE_STR(x) DRAPE_STR2(x)
  return DRAPE_STR(DRAPE_VERSION_MAJOR) "." DRAPE_STR(DRAPE_VERSION_MINOR) "." DRAPE_STR(DRAPE_VERSION_PATCH);
#undef DRAPE_STR
#undef DRAPE_STR2
}

}  // extern "C"
