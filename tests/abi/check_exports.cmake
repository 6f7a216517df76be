# Compares the dynamic symbols the shared library exports with the committed list, so an
# accidental ABI change (a symbol added, removed or renamed) fails the test suite.
# Usage: cmake -DLIB=<libdrape.so> -DEXPECTED=<exported_symbols.txt> -P check_exports.cmake
# To accept an intended change: nm -D --defined-only libdrape.so | awk '{print $3}' | sort > exported_symbols.txt
find_program(NM_TOOL NAMES nm REQUIRED)
execute_process(COMMAND ${NM_TOOL} -D --defined-only ${LIB}
                OUTPUT_VARIABLE nm_out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
string(REPLACE "\n" ";" lines "${nm_out}")
set(actual)
foreach(line IN LISTS lines)
  if(line MATCHES "^[0-9a-fA-F]+ [A-Za-z] ([^ ]+)$")
    list(APPEND actual "${CMAKE_MATCH_1}")
  endif()
endforeach()
list(SORT actual)
file(STRINGS ${EXPECTED} expected)
list(SORT expected)
set(added ${actual})
list(REMOVE_ITEM added ${expected})
set(removed ${expected})
list(REMOVE_ITEM removed ${actual})
if(added OR removed)
  message(FATAL_ERROR "Exported symbols differ from ${EXPECTED}:\n  added: ${added}\n  removed: ${removed}\n"
                      "If the ABI change is intended, update the list (see the header of this script).")
endif()
list(LENGTH actual n)
message(STATUS "ABI check: ${n} exported symbols match the committed list")
