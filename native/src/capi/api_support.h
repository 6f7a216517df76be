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

// Handles are opaque tokens, not addresses: each create hands out a value never used before, so a
// destroyed handle stays invalid even when the allocator gives its memory to a new object, and a
// context token is never a valid recording token. Tokens are never dereferenced.
enum class HandleKind { Context, Recording, Garment };
// Registers `object` and returns its token. Throws std::bad_alloc only (caught by guarded()).
void* registerHandle(HandleKind kind, void* object);
// The object behind a live token of this kind, or nullptr.
void* resolveHandle(HandleKind kind, const void* token);
// Forgets a live token and returns its object (nullptr if the token is not live).
void* unregisterHandle(HandleKind kind, const void* token);

// The entry point now running on this thread (set by guarded()); fail() prefixes it to messages
// that do not already name it.
void setCurrentFunction(const char* function);

// Resolves a drape_context* argument into `Context* const var` or returns the error (NULL or not a
// live context). For the entry points in capi_context.cpp and capi_garments.cpp.
#define DRAPE_RESOLVE_CONTEXT(var, fn, handle)                                                     \
  if (!(handle)) return ::drape::api::fail(DRAPE_ERROR_NULL_ARGUMENT, fn ": context is NULL");    \
  ::drape::Context* const var =                                                                  \
      static_cast<::drape::Context*>(::drape::api::resolveHandle(::drape::api::HandleKind::Context, handle)); \
  if (!var)                                                                                      \
  return ::drape::api::fail(DRAPE_ERROR_INVALID_HANDLE, fn ": context is not a live drape_context (destroyed or never created)")

const char* lastError();

// Validates the struct_size field of a caller struct: at least the first released size.
drape_result checkStructSize(uint32_t struct_size, size_t min_size, const char* what);

// Validates the arguments of a sized init (drape_*_init_sized): `object` (named `what` in the
// message) not NULL, struct_size from the struct's first layout to this library's sizeof (a larger
// one comes from a header newer than the library). Nothing is written when it fails.
drape_result checkSizedInit(const char* fn, const void* object, const char* what, uint32_t struct_size,
                            size_t first_size, size_t current_size);

inline bool finite(float v) { return std::isfinite(v); }
inline bool finite(double v) { return std::isfinite(v); }

// Runs `body` (returning drape_result), mapping exceptions to result codes.
template <typename F>
drape_result guarded(const char* function, F&& body) noexcept {
  // Names the entry point for fail() while it runs, and only then.
  struct Scope {
    explicit Scope(const char* f) { setCurrentFunction(f); }
    ~Scope() { setCurrentFunction(nullptr); }
  } scope(function);
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
