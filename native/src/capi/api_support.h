// What every C entry point shares: the thread-local last error, the registry of live handles
// (so a stale pointer is rejected without being dereferenced), and the guard that turns any C++
// exception into a result code before it can cross the ABI.
#pragma once

#include "drape/drape.h"

#include <cmath>
#include <new>
#include <string>

namespace drape::api {

// Records `message` as the calling thread's last error and returns `result`.
drape_result fail(drape_result result, const std::string& message);
// Clears nothing: a success leaves the last error of an earlier failure readable.
inline drape_result ok() { return DRAPE_OK; }

enum class HandleKind { Context, Recording };
void registerHandle(HandleKind kind, const void* handle);
void unregisterHandle(HandleKind kind, const void* handle);
bool isLiveHandle(HandleKind kind, const void* handle);

// Validates the struct_size field of a caller struct: at least the first released size.
const char* lastError();

drape_result checkStructSize(uint32_t struct_size, size_t min_size, const char* what);

inline bool finite(float v) { return std::isfinite(v); }
inline bool finite(double v) { return std::isfinite(v); }

// Runs `body` (returning drape_result), mapping exceptions to result codes.
template <typename F>
drape_result guarded(const char* function, F&& body) noexcept {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return fail(DRAPE_ERROR_OUT_OF_MEMORY, std::string(function) + ": out of memory");
  } catch (const std::exception& e) {
    return fail(DRAPE_ERROR_INTERNAL, std::string(function) + ": internal error: " + e.what());
  } catch (...) {
    return fail(DRAPE_ERROR_INTERNAL, std::string(function) + ": internal error");
  }
}

}  // namespace drape::api
