# Runs drape-replay and checks its stats JSON (ctest: replay_default, replay_no_garment,
# replay_garment_obj, replay_bvh).
#   cmake -DEXE=... -DOUT_DIR=... -DARGS="a|b|c" -DEXPECT_FRAMES=N -DEXPECT_OBJ=N
#         [-DEXPECT_GARMENT=template|obj|none -DEXPECT_GARMENT_OBJ=N -DEXPECT_MEASURED=N]
#         [-DEXPECT_SUBSTEP_HZ=N (garment.substep_hz)] [-DEXPECT_UNDER=kind (--under; garment.under)]
#         [-DEXPECT_STRAIN_LIMIT_PASSES=N (garment.strain_limit_passes)]
#         [-DEXPECT_FORMAT=kinect_csv] [-DEXPECT_BACKEND=cpu|opencl] [-DVOLUME_MIN_L=x -DVOLUME_MAX_L=y] [-DPYTHON=python3]
#         [-DEXPECT_RENDERED=N -DEXPECT_PNG_SIZE=WxH -DEXPECT_SHEET=ON|OFF -DEXPECT_GIF=ON|OFF]
#         -P check_stats.cmake
# EXPECT_GARMENT (default template) is garment.source. With a garment it requires particles > 0,
# every garment number finite (a JSON number, not null) and one step per updated frame; with
# none, particles = 0 and the cloth keys null. No physics quality bounds (stretch, penetration):
# those belong to the cloth tests and benchmarks.
# EXPECT_RENDERED is render.frames_rendered and the number of render_*.png files; with N > 0 the
# first one must be a PNG (signature, IHDR) of EXPECT_PNG_SIZE pixels. EXPECT_SHEET=ON requires
# contact_sheet.png, a valid PNG named by render.contact_sheet; EXPECT_GIF=ON requires replay.gif
# starting "GIF89a" and named by render.gif; OFF requires the key null.
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
             "garment|kind" "garment|source" "garment|solver" "garment|substep_hz" "garment|iterations" "garment|triangles"
             "garment|edges" "garment|attached" "garment|frames_stepped" "garment|max_stretch"
             "garment|p99_stretch" "garment|body_surface_stretch|edges" "garment|body_surface_stretch|p99"
             "garment|body_surface_stretch|max" "garment|body_surface_stretch|over_5pct"
             "garment|body_surface_stretch|tubes|edges" "garment|body_surface_stretch|tubes|p99"
             "garment|body_surface_stretch|tubes|over_5pct" "garment|proxy_inside" "garment|body_penetration_mm|p99"
             "garment|body_penetration_mm|max" "garment|deeper_than_2mm" "garment|inside_body" "garment|openings|tracked"
             "garment|openings|off_frames" "garment|openings|off_max" "garment|frames_measured"
             "garment|teleport_resets" "garment|nan_resets" "garment|contacts" "garment|substeps" "garment|under"
             "render|frames_rendered" "render|every" "render|camera" "render|width" "render|height"
             "render|contact_sheet" "render|gif" "render|mp4" "render|ms_per_frame_median")
  string(REPLACE "|" ";" _keys "${path}")
  json_get(_unused ${_keys})
endforeach()

# The adaptive pipeline's counters (docs/adaptive.md). EXPECT_FULL_PIPELINE=ON (--full-pipeline):
# every ellipsoid built every frame, nothing skipped, nothing slept; OFF: a garment world builds
# fewer ellipsoids than there are (proxy culling).
foreach(path "skipped|full_pipeline" "skipped|proxies_built" "skipped|proxies_available"
             "skipped|stages_skipped" "skipped|frames_slept")
  string(REPLACE "|" ";" _keys "${path}")
  json_get(_unused ${_keys})
endforeach()
if(DEFINED EXPECT_FULL_PIPELINE)
  json_get(_sk_full skipped full_pipeline)
  json_get(_sk_built skipped proxies_built)
  json_get(_sk_avail skipped proxies_available)
  json_get(_sk_stages skipped stages_skipped)
  json_get(_sk_slept skipped frames_slept)
  if(NOT _sk_avail GREATER 0)
    string(APPEND _failures "  skipped.proxies_available = ${_sk_avail}, expected > 0\n")
  endif()
  if(EXPECT_FULL_PIPELINE)
    if(NOT _sk_full STREQUAL "ON" AND NOT _sk_full STREQUAL "true")
      string(APPEND _failures "  skipped.full_pipeline = ${_sk_full}, expected true\n")
    endif()
    expect_equal("skipped.proxies_built" "${_sk_built}" "${_sk_avail}")
    expect_equal("skipped.stages_skipped" "${_sk_stages}" 0)
    expect_equal("skipped.frames_slept" "${_sk_slept}" 0)
  else()
    if(NOT _sk_full STREQUAL "OFF" AND NOT _sk_full STREQUAL "false")
      string(APPEND _failures "  skipped.full_pipeline = ${_sk_full}, expected false\n")
    endif()
    if(NOT _sk_built LESS _sk_avail)
      string(APPEND _failures "  skipped.proxies_built = ${_sk_built}, expected < ${_sk_avail} (culled)\n")
    endif()
  endif()
endif()

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
    "garment|max_stretch" "garment|p99_stretch" "garment|body_surface_stretch|p99"
    "garment|body_surface_stretch|over_5pct" "garment|body_surface_stretch|tubes|p99" "garment|contacts"
    "garment|substeps")
set(_garment_measured "garment|body_penetration_mm|p99" "garment|body_penetration_mm|max"
    "garment|deeper_than_2mm" "garment|inside_body")
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
  # The body's surface under the garment: some of the body's edges, the tubes' a part of them.
  json_get(_bs_edges garment body_surface_stretch edges)
  json_get(_bs_tubes garment body_surface_stretch tubes edges)
  if(NOT _bs_edges GREATER 0 OR NOT _bs_tubes GREATER 0 OR _bs_tubes GREATER _bs_edges)
    string(APPEND _failures "  garment.body_surface_stretch: ${_bs_edges} edges, ${_bs_tubes} of them the tubes'; "
                            "expected 0 < tubes <= edges\n")
  endif()
  json_get(_gmeasured garment frames_measured)
  if(DEFINED EXPECT_MEASURED)
    expect_equal("garment.frames_measured" "${_gmeasured}" "${EXPECT_MEASURED}")
  endif()
  if(DEFINED EXPECT_SUBSTEP_HZ)
    json_get(_ghz garment substep_hz)
    expect_equal("garment.substep_hz" "${_ghz}" "${EXPECT_SUBSTEP_HZ}")
  endif()
  if(DEFINED EXPECT_STRAIN_LIMIT_PASSES)
    json_get(_gslp garment strain_limit_passes)
    expect_equal("garment.strain_limit_passes" "${_gslp}" "${EXPECT_STRAIN_LIMIT_PASSES}")
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

# --under (EXPECT_UNDER=<kind>): the garment under it, its OBJs (EXPECT_GARMENT_OBJ of them) and the
# crossing measured on every measured frame; without it garment.under is null.
if(DEFINED EXPECT_UNDER)
  json_get(_ukind garment under kind)
  if(NOT _ukind STREQUAL EXPECT_UNDER)
    string(APPEND _failures "  garment.under.kind = ${_ukind}, expected ${EXPECT_UNDER}\n")
  endif()
  json_get(_uparticles garment under particles)
  json_get(_uframes garment under crossing frames)
  json_get(_uover garment under crossing over)
  json_get(_gmeasured2 garment frames_measured)
  expect_type(NUMBER garment under crossing under_share)
  json_get(_ushare garment under crossing under_share)
  if(NOT _uparticles GREATER 0 OR NOT _uover GREATER 0 OR _ushare LESS 0 OR _ushare GREATER 1)
    string(APPEND _failures "  garment.under: ${_uparticles} particles, crossing over ${_uover}, share ${_ushare}; "
                            "expected particles > 0, over > 0, 0 <= share <= 1\n")
  endif()
  expect_equal("garment.under.crossing.frames" "${_uframes}" "${_gmeasured2}")
  if(DEFINED EXPECT_GARMENT_OBJ)
    file(GLOB _uobjs "${OUT_DIR}/under_*.obj")
    list(LENGTH _uobjs _uobj_count)
    expect_equal("under OBJ files" "${_uobj_count}" "${EXPECT_GARMENT_OBJ}")
  endif()
else()
  expect_type(NULL garment under)
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

# Pictures.
# Reads a PNG's signature and IHDR size into <out_w> <out_h> (empty when it is not a PNG).
function(png_size path out_w out_h)
  set(${out_w} "" PARENT_SCOPE)
  set(${out_h} "" PARENT_SCOPE)
  if(NOT EXISTS "${path}")
    return()
  endif()
  file(READ "${path}" _hex LIMIT 24 HEX)
  # 8-byte signature, then the IHDR chunk: length 13, "IHDR", width, height (big-endian).
  string(LENGTH "${_hex}" _len)
  if(NOT _len EQUAL 48 OR NOT _hex MATCHES "^89504e470d0a1a0a0000000d49484452")
    return()
  endif()
  string(SUBSTRING "${_hex}" 32 8 _w_hex)
  string(SUBSTRING "${_hex}" 40 8 _h_hex)
  math(EXPR _w "0x${_w_hex}")
  math(EXPR _h "0x${_h_hex}")
  set(${out_w} "${_w}" PARENT_SCOPE)
  set(${out_h} "${_h}" PARENT_SCOPE)
endfunction()
expect_type(NUMBER render frames_rendered)
if(DEFINED EXPECT_RENDERED)
  json_get(_rendered render frames_rendered)
  expect_equal("render.frames_rendered" "${_rendered}" "${EXPECT_RENDERED}")
  file(GLOB _pngs "${OUT_DIR}/render_*.png")
  list(LENGTH _pngs _png_count)
  expect_equal("render_*.png files" "${_png_count}" "${EXPECT_RENDERED}")
  if(_png_count GREATER 0)
    list(SORT _pngs)
    list(GET _pngs 0 _first_png)
    png_size("${_first_png}" _pw _ph)
    if(_pw STREQUAL "")
      string(APPEND _failures "  ${_first_png} is not a PNG (signature + IHDR)\n")
    elseif(DEFINED EXPECT_PNG_SIZE AND NOT "${_pw}x${_ph}" STREQUAL EXPECT_PNG_SIZE)
      string(APPEND _failures "  ${_first_png} is ${_pw}x${_ph}, expected ${EXPECT_PNG_SIZE}\n")
    endif()
  endif()
endif()
if(DEFINED EXPECT_SHEET)
  if(EXPECT_SHEET)
    json_get(_sheet render contact_sheet)
    png_size("${OUT_DIR}/contact_sheet.png" _sw _sh)
    if(_sw STREQUAL "" OR NOT _sw GREATER 0 OR NOT _sh GREATER 0)
      string(APPEND _failures "  ${OUT_DIR}/contact_sheet.png is missing or not a PNG\n")
    endif()
    if(NOT _sheet MATCHES "contact_sheet\\.png$")
      string(APPEND _failures "  render.contact_sheet = '${_sheet}', expected the contact_sheet.png path\n")
    endif()
  else()
    expect_type(NULL render contact_sheet)
  endif()
endif()
if(DEFINED EXPECT_GIF)
  if(EXPECT_GIF)
    json_get(_gif render gif)
    set(_gif_header "")
    if(EXISTS "${OUT_DIR}/replay.gif")
      file(READ "${OUT_DIR}/replay.gif" _gif_header LIMIT 6 HEX)
    endif()
    if(NOT _gif_header STREQUAL "474946383961")  # "GIF89a"
      string(APPEND _failures "  ${OUT_DIR}/replay.gif is missing or does not start with GIF89a\n")
    endif()
    if(NOT _gif MATCHES "replay\\.gif$")
      string(APPEND _failures "  render.gif = '${_gif}', expected the replay.gif path\n")
    endif()
  else()
    expect_type(NULL render gif)
  endif()
endif()

# EXPECT_BACKEND (optional): stats.backend; "opencl" also needs a device name.
if(DEFINED EXPECT_BACKEND)
  json_get(_backend backend)
  if(NOT _backend STREQUAL EXPECT_BACKEND)
    json_get(_fallback backend_fallback)
    string(APPEND _failures "  backend = ${_backend}, expected ${EXPECT_BACKEND} (fallback: ${_fallback})\n")
  elseif(EXPECT_BACKEND STREQUAL "opencl")
    json_get(_device device)
    if(_device STREQUAL "" OR _device STREQUAL "NOTFOUND" OR _device MATCHES "NOTFOUND$")
      string(APPEND _failures "  device is empty with backend opencl\n")
    endif()
  endif()
endif()

if(_failures)
  message(FATAL_ERROR "drape-replay stats check failed:\n${_failures}")
endif()
message(STATUS "drape-replay stats OK: ${_frames} frames, ${_watertight} watertight, ${_volume} L, ${_obj_count} body OBJ files, garment ${_source} with ${_particles} particles")
