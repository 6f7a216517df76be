#include "capi/api_support.h"

#include <cstring>
#include <mutex>
#include <unordered_map>

namespace drape::api {

namespace {

thread_local std::string t_lastError;
thread_local const char* t_currentFunction = nullptr;

struct Registry {
  std::mutex mutex;
  uintptr_t next = 0;  // tokens are (++next) << 4: never 0, never reused (2^60 creates on 64-bit)
  struct Entry {
    HandleKind kind;
    void* object;
  };
  std::unordered_map<uintptr_t, Entry> live;
};

Registry& registry() {
  static Registry* r = new Registry();  // never destroyed: safe to use during static teardown
  return *r;
}

}  // namespace

void setCurrentFunction(const char* function) { t_currentFunction = function; }

drape_result fail(drape_result result, const std::string& message) {
  try {
    const char* fn = t_currentFunction;
    if (fn && message.compare(0, std::strlen(fn), fn) != 0)
      t_lastError = std::string(fn) + ": " + message;
    else
      t_lastError = message;
  } catch (...) {
    // Could not allocate the message: keep the code, which is what callers act on.
  }
  return result;
}

void* registerHandle(HandleKind kind, void* object) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const uintptr_t token = (++r.next) << 4;
  r.live.emplace(token, Registry::Entry{kind, object});
  return reinterpret_cast<void*>(token);
}

void* resolveHandle(HandleKind kind, const void* token) {
  if (!token) return nullptr;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.live.find(reinterpret_cast<uintptr_t>(token));
  return (it != r.live.end() && it->second.kind == kind) ? it->second.object : nullptr;
}

void* unregisterHandle(HandleKind kind, const void* token) {
  if (!token) return nullptr;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.live.find(reinterpret_cast<uintptr_t>(token));
  if (it == r.live.end() || it->second.kind != kind) return nullptr;
  void* object = it->second.object;
  r.live.erase(it);
  return object;
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

drape_result checkSizedInit(const char* fn, const void* object, const char* what, uint32_t struct_size,
                            size_t first_size, size_t current_size) {
  if (!object) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": " + what + " is NULL");
  if (struct_size < first_size || struct_size > current_size) {
    return fail(DRAPE_ERROR_INVALID_ARGUMENT,
                std::string(fn) + ": struct_size is " + std::to_string(struct_size) + ", expected " +
                    std::to_string(first_size) + " to " + std::to_string(current_size) +
                    " (a larger one comes from a header newer than this library)");
  }
  return DRAPE_OK;
}

const char* lastError() { return t_lastError.c_str(); }

}  // namespace drape::api

extern "C" {

DRAPE_API const char* DRAPE_CALL drape_last_error(void) { return drape::api::lastError(); }

DRAPE_API const char* DRAPE_CALL drape_result_name(drape_result result) {
  // A C caller may pass any int here, and in C++ reading an enum object that holds a value outside
  // the enum's range is undefined (clang's UBSan reports it): the code is read as its bytes.
  int32_t code = 0;
  static_assert(sizeof(result) == sizeof(code), "drape_result is int-sized in C and C++");
  std::memcpy(&code, &result, sizeof(code));
  switch (code) {
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
