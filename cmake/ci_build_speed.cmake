# Compile-time savings for the trees CI builds from scratch on every run (docs/robustness.md, "CI
# time"). With ASan + UBSan instrumentation every translation unit costs 2-3 times its release
# compile, and the test programs are half of the release tree's compile time. The library of the
# release tree stays a plain build (no precompiled headers, no unity batches), so CI still proves
# that each of its files compiles on its own, with its own includes; every option is off by default.
#
# DRAPE_PRECOMPILE_HEADERS: Eigen, the standard headers nearly every file includes and (for the
#   test programs) GoogleTest parsed once per target instead of once per file - library and tests
#   (sanitizer presets).
# DRAPE_PRECOMPILE_TEST_HEADERS: the same for the test programs alone (release preset).
# DRAPE_UNITY_TESTS: the GoogleTest files of drape_tests compiled 8 to a translation unit, so
#   GoogleTest's and Eigen's templates are instantiated (and instrumented) once per batch (release
#   and sanitizer presets). Test files whose file-local helpers clash with another file's (same
#   name in an anonymous namespace) are compiled on their own; a new clash shows as "redefinition
#   of ..." or "call of overloaded ... is ambiguous": rename the helper or add the file to the
#   list below.
# DRAPE_UNITY_CORE: the library's files compiled 8 to a translation unit (sanitizer preset `asan`:
#   219 s of CPU instead of 287 s on the Zen 1). The release tree still compiles every library file
#   on its own. Files with per-file compile options (the readers that carry libFuzzer's coverage,
#   top-level CMakeLists.txt) are compiled alone. A new clash between two library files' file-local
#   helpers shows as "redefinition of ...": share the helper in a header (as sanitizeState in
#   skeleton/joints.h and release(cl_mem&) in backends/opencl/cl_runtime.h) or rename it.
option(DRAPE_PRECOMPILE_HEADERS "Precompiled headers for drape_core and the test programs (sanitizer presets)" OFF)
option(DRAPE_PRECOMPILE_TEST_HEADERS "Precompiled headers for the test programs alone (release preset)" OFF)
option(DRAPE_UNITY_TESTS "Compile drape_tests as unity batches of 8 files (release and sanitizer presets)" OFF)
option(DRAPE_UNITY_CORE "Compile drape_core as unity batches of 8 files (sanitizer preset asan)" OFF)

set(_drape_pch_common <Eigen/Core> <Eigen/Geometry> <algorithm> <cmath> <cstdint> <cstring> <limits>
    <memory> <string> <vector>)

if(DRAPE_PRECOMPILE_HEADERS AND TARGET drape_core)
  target_precompile_headers(drape_core PRIVATE ${_drape_pch_common})
endif()
if(DRAPE_PRECOMPILE_HEADERS OR DRAPE_PRECOMPILE_TEST_HEADERS)
  foreach(_t drape_tests drape_stress_tests drape_fuzz_regressions)
    if(TARGET ${_t})
      target_precompile_headers(${_t} PRIVATE ${_drape_pch_common} <gtest/gtest.h>)
    endif()
  endforeach()
endif()

if(DRAPE_UNITY_TESTS AND TARGET drape_tests)
  set_target_properties(drape_tests PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  # Clashing file-local names (as of this writing): square() in test_cloth_xpbd.cpp, Mesh in
  # test_fidelity.cpp, Take in test_skeleton_tracker.cpp. test_cloth_strain_limit.cpp and
  # test_arm_clearance.cpp clash with nothing, but a file added in the middle of the sorted list
  # regroups every batch after it, and regrouped files met other files' names (Body in test_garment_obj.cpp and
  # test_garment_templates.cpp, since renamed ObjTestBody): kept out, the batches stay as they were.
  set_source_files_properties(
      "${PROJECT_SOURCE_DIR}/tests/native/test_arm_clearance.cpp"
      "${PROJECT_SOURCE_DIR}/tests/native/test_cloth_strain_limit.cpp"
      "${PROJECT_SOURCE_DIR}/tests/native/test_cloth_xpbd.cpp"
      "${PROJECT_SOURCE_DIR}/tests/native/test_fidelity.cpp"
      "${PROJECT_SOURCE_DIR}/tests/native/test_skeleton_tracker.cpp"
    DIRECTORY "${PROJECT_SOURCE_DIR}/tests"
    PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
endif()

if(DRAPE_UNITY_CORE AND TARGET drape_core)
  set_target_properties(drape_core PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
endif()
