# Runs drape-replay and requires an exact exit code (ctest: replay_bad_args, replay_missing_file).
#   cmake -DEXE=... -DARGS="a|b" -DEXPECT_RC=2 -P check_exit_code.cmake
# For a non-zero code it also requires exactly one stderr line starting "drape-replay: error: ".
cmake_minimum_required(VERSION 3.25)

if(NOT DEFINED EXE OR NOT DEFINED EXPECT_RC)
  message(FATAL_ERROR "check_exit_code.cmake: -DEXE=... and -DEXPECT_RC=... are required")
endif()
string(REPLACE "|" ";" _args "${ARGS}")
execute_process(COMMAND "${EXE}" ${_args} RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
message("exit code: ${_rc}\nstdout: ${_out}\nstderr: ${_err}")
if(NOT _rc STREQUAL "${EXPECT_RC}")
  message(FATAL_ERROR "drape-replay ${ARGS} exited with '${_rc}', expected exactly ${EXPECT_RC}")
endif()
if(NOT EXPECT_RC STREQUAL "0")
  if(NOT _err MATCHES "^drape-replay: error: [^\n]+\n$")
    message(FATAL_ERROR "stderr is not one line starting 'drape-replay: error: ': '${_err}'")
  endif()
endif()
