# Runs drape-replay and checks its stats JSON (ctest: replay_default, replay_no_garment,
# replay_garment_obj, replay_bvh).
#   cmake -DEXE=... -DOUT_DIR=... -DARGS="a|b|c" -DEXPECT_FRAMES=N -DEXPECT_OBJ=N
#         [-DEXPECT_GARMENT=template|obj|none -DEXPECT_GARMENT_OBJ=N -DEXPECT_MEASURED=N]
#         [-DEXPECT_FORMAT=kinect_csv] [-DVOLUME_MIN_L=x -DVOLUME_MAX_L=y] [-DPYTHON=python3]
#         -P check_stats.cmake
# EXPECT_GARMENT (default template) is garment.source. With a garment it requires particles > 0,
# every garment number finite (a JSON number, not null) and one step per updated frame; with
# none, particles = 0 and the cloth keys null. No physics quality bounds (stretch, penetration):
# those belong to the cloth tests and benchmarks.
# The program is run with --out OUT_DIR (emptied first) plus ARGS; stats are read from
# OUT_DIR/stats.json with string(JSON), so no Python is needed (PYTHON, when given, also runs
# `python3 -m json.tool` on the file).
cmake_minimum_required(VERSION 3.25)

foreach(var EXE OUT_DIR EXPECT_FRAMES EXPECT_OBJ)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_stats.cmake: -D${var}=... is required")
  endif()
endforeach()

string(REPLACE "|" ";" _args "${ARGS}")
file(REMOVE_RECURSE "${OUT_DIR}")
execute_process(COMMAND "${EXE}" --out "${OUT_DIR}" ${_args}
                RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
message("${_out}")
if(_err)
  message("stderr:\n${_err}")
endif()
if(NOT _rc STREQUAL "0")
  message(FATAL_ERROR "drape-replay exited with ${_rc}, expected 0")
endif()

set(_stats "${OUT_DIR}/stats.json")
if(NOT EXISTS "${_stats}")
  message(FATAL_ERROR "${_stats} was not written")
endif()
file(READ "${_stats}" _json)
message("stats.json:\n${_json}")

if(PYTHON)
  execute_process(COMMAND "${PYTHON}" -m json.tool "${_stats}" RESULT_VARIABLE _py_rc
                  OUTPUT_QUIET ERROR_VARIABLE _py_err)
  if(NOT _py_rc STREQUAL "0")
    message(FATAL_ERROR "python3 -m json.tool rejects ${_stats}: ${_py_err}")
  endif()
endif()

set(_failures "")
macro(json_get out)
  string(JSON ${out} ERROR_VARIABLE _json_err GET "${_json}" ${ARGN})
  if(_json_err)
    string(APPEND _failures "  missing or malformed key ${ARGN}: ${_json_err}\n")
  endif()
endmacro()
macro(expect_equal what actual expected)
  if(NOT "${actual}" EQUAL "${expected}")
    string(APPEND _failures "  ${what} = ${actual}, expected ${expected}\n")
  endif()
endmacro()

# Every key of the contract must be present (docs/replay.md).
foreach(path "drape_version" "recording" "format" "layout" "frames" "rejected_frames" "teleports"
             "nonfinite" "ms_per_frame|median" "ms_per_frame|p90" "ms_per_frame|max"
             "stages_ms|skeleton" "stages_ms|body" "body|vertices" "body|triangles"
             "body|watertight_frames" "body|volume_l" "shape|height_m" "shape|weight_kg"
             "shape|neck_mm" "shape|chest_mm" "shape|waist_mm" "shape|hip_mm" "shape|thigh_mm"
             "shape|calf_mm" "shape|upper_arm_mm" "shape|forearm_mm" "ring_points"
             "stages_ms|proxies" "proxies|count" "proxies|rule" "proxies|frames_measured"
             "proxies|fit_p95_mm" "proxies|fit_max_mm" "proxies|outside_fraction"
             "stages_ms|cloth" "stages_ms|integrate" "stages_ms|collide" "stages_ms|frame" "particles"
             "garment|kind" "garment|source" "garment|solver" "garment|substep_hz" "garment|triangles"
             "garment|edges" "garment|attached" "garment|frames_stepped" "garment|max_stretch"
             "garment|p99_stretch" "garment|proxy_inside" "garment|body_penetration_mm|p99"
             "garment|body_penetration_mm|max" "garment|deeper_than_2mm" "garment|frames_measured"
             "garment|teleport_resets" "garment|nan_resets" "garment|contacts" "garment|substeps")
  string(REPLACE "|" ";" _keys "${path}")
  json_get(_unused ${_keys})
endforeach()

json_get(_frames frames)
json_get(_rejected rejected_frames)
json_get(_nonfinite nonfinite)
json_get(_watertight body watertight_frames)
json_get(_vertices body vertices)
json_get(_volume body volume_l)
json_get(_format format)

expect_equal("frames" "${_frames}" "${EXPECT_FRAMES}")
expect_equal("rejected_frames" "${_rejected}" 0)
expect_equal("nonfinite" "${_nonfinite}" 0)
expect_equal("body.watertight_frames" "${_watertight}" "${_frames}")
if(DEFINED EXPECT_FORMAT AND NOT _format STREQUAL EXPECT_FORMAT)
  string(APPEND _failures "  format = ${_format}, expected ${EXPECT_FORMAT}\n")
endif()
if(DEFINED VOLUME_MIN_L)
  # if(LESS/GREATER) compare as floating-point numbers.
  if(NOT _volume MATCHES "^[0-9.eE+-]+$" OR _volume LESS VOLUME_MIN_L OR _volume GREATER VOLUME_MAX_L)
    string(APPEND _failures "  body.volume_l = ${_volume}, expected within [${VOLUME_MIN_L}, ${VOLUME_MAX_L}]\n")
  endif()
endif()

# Tracking ellipsoids: present, measured, and within FIT_P95_MAX_MM (the target is 10 mm).
json_get(_proxy_count proxies count)
json_get(_fit_p95 proxies fit_p95_mm)
json_get(_measured proxies frames_measured)
if(NOT _proxy_count GREATER 0)
  string(APPEND _failures "  proxies.count = ${_proxy_count}, expected > 0\n")
endif()
if(DEFINED FIT_P95_MAX_MM AND _measured GREATER 0 AND
   (NOT _fit_p95 MATCHES "^[0-9.eE+-]+$" OR _fit_p95 GREATER FIT_P95_MAX_MM))
  string(APPEND _failures "  proxies.fit_p95_mm = ${_fit_p95}, expected <= ${FIT_P95_MAX_MM}\n")
endif()

file(GLOB _objs "${OUT_DIR}/body_*.obj")
list(LENGTH _objs _obj_count)
expect_equal("OBJ files" "${_obj_count}" "${EXPECT_OBJ}")
if(_obj_count GREATER 0)
  list(SORT _objs)
  list(GET _objs 0 _first)
  file(STRINGS "${_first}" _v REGEX "^v ")
  file(STRINGS "${_first}" _vn REGEX "^vn ")
  file(STRINGS "${_first}" _f REGEX "^f [0-9]+//[0-9]+ [0-9]+//[0-9]+ [0-9]+//[0-9]+$")
  list(LENGTH _v _nv)
  list(LENGTH _vn _nvn)
  list(LENGTH _f _nf)
  json_get(_triangles body triangles)
  expect_equal("v lines in ${_first}" "${_nv}" "${_vertices}")
  expect_equal("vn lines in ${_first}" "${_nvn}" "${_vertices}")
  expect_equal("f lines in ${_first}" "${_nf}" "${_triangles}")
endif()

# The garment.
if(NOT DEFINED EXPECT_GARMENT)
  set(EXPECT_GARMENT template)
endif()
macro(expect_type type)
  string(JSON _t ERROR_VARIABLE _json_err TYPE "${_json}" ${ARGN})
  if(NOT _json_err AND NOT _t STREQUAL "${type}")
    string(REPLACE ";" "." _k "${ARGN}")
    string(APPEND _failures "  ${_k} is ${_t}, expected ${type}\n")
  endif()
endmacro()
json_get(_particles particles)
json_get(_source garment source)
json_get(_stepped garment frames_stepped)
json_get(_gtriangles garment triangles)
if(NOT _source STREQUAL EXPECT_GARMENT)
  string(APPEND _failures "  garment.source = ${_source}, expected ${EXPECT_GARMENT}\n")
endif()
set(_garment_numbers "stages_ms|cloth" "stages_ms|integrate" "stages_ms|collide" "garment|substep_hz"
    "garment|max_stretch" "garment|p99_stretch" "garment|contacts" "garment|substeps")
set(_garment_measured "garment|body_penetration_mm|p99" "garment|body_penetration_mm|max"
    "garment|deeper_than_2mm")
expect_type(NUMBER stages_ms frame)
if(EXPECT_GARMENT STREQUAL "none")
  expect_equal("particles" "${_particles}" 0)
  expect_equal("garment.frames_stepped" "${_stepped}" 0)
  json_get(_kind garment kind)
  if(NOT _kind STREQUAL "none")
    string(APPEND _failures "  garment.kind = ${_kind}, expected none\n")
  endif()
  expect_type(NULL garment solver)
  foreach(path IN LISTS _garment_numbers _garment_measured)
    string(REPLACE "|" ";" _keys "${path}")
    expect_type(NULL ${_keys})
  endforeach()
else()
  if(NOT _particles GREATER 0)
    string(APPEND _failures "  particles = ${_particles}, expected > 0\n")
  endif()
  if(NOT _gtriangles GREATER 0)
    string(APPEND _failures "  garment.triangles = ${_gtriangles}, expected > 0\n")
  endif()
  math(EXPR _updated "${_frames} - ${_rejected}")
  expect_equal("garment.frames_stepped" "${_stepped}" "${_updated}")
  foreach(path IN LISTS _garment_numbers)
    string(REPLACE "|" ";" _keys "${path}")
    expect_type(NUMBER ${_keys})
  endforeach()
  json_get(_gmeasured garment frames_measured)
  if(DEFINED EXPECT_MEASURED)
    expect_equal("garment.frames_measured" "${_gmeasured}" "${EXPECT_MEASURED}")
  endif()
  if(_gmeasured GREATER 0)
    foreach(path IN LISTS _garment_measured)
      string(REPLACE "|" ";" _keys "${path}")
      expect_type(NUMBER ${_keys})
    endforeach()
  endif()
  foreach(path "garment|edges" "garment|attached" "garment|proxy_inside" "garment|frames_measured"
               "garment|teleport_resets" "garment|nan_resets" "garment|triangles")
    string(REPLACE "|" ";" _keys "${path}")
    expect_type(NUMBER ${_keys})
  endforeach()
  json_get(_edges garment edges)
  if(NOT _edges GREATER 0)
    string(APPEND _failures "  garment.edges = ${_edges}, expected > 0\n")
  endif()
endif()

if(DEFINED EXPECT_GARMENT_OBJ)
  file(GLOB _gobjs "${OUT_DIR}/garment_*.obj")
  list(LENGTH _gobjs _gobj_count)
  expect_equal("garment OBJ files" "${_gobj_count}" "${EXPECT_GARMENT_OBJ}")
  if(_gobj_count GREATER 0)
    list(SORT _gobjs)
    list(GET _gobjs 0 _first)
    file(STRINGS "${_first}" _v REGEX "^v ")
    file(STRINGS "${_first}" _vn REGEX "^vn ")
    file(STRINGS "${_first}" _f REGEX "^f [0-9]+//[0-9]+ [0-9]+//[0-9]+ [0-9]+//[0-9]+$")
    list(LENGTH _v _nv)
    list(LENGTH _vn _nvn)
    list(LENGTH _f _nf)
    expect_equal("v lines in ${_first}" "${_nv}" "${_particles}")
    expect_equal("vn lines in ${_first}" "${_nvn}" "${_particles}")
    expect_equal("f lines in ${_first}" "${_nf}" "${_gtriangles}")
  endif()
endif()

if(_failures)
  message(FATAL_ERROR "drape-replay stats check failed:\n${_failures}")
endif()
message(STATUS "drape-replay stats OK: ${_frames} frames, ${_watertight} watertight, ${_volume} L, ${_obj_count} body OBJ files, garment ${_source} with ${_particles} particles")
