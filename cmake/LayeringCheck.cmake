# Fails when an include crosses the project's layers the wrong way (docs/architecture.md §1).
#
# Inside seep::core each folder has a rank; a file may include its own folder and folders of a
# lower rank only (two folders of the same rank are independent of each other):
#
#   0 base (status, log, threads)   1 geometry   2 dem, flow   3 coupling   4 spec   5 network
#   6 calibration, reference        7 effects    8 run
#
# Across the project: no protobuf, gRPC or SQLite header in core; SQLite only in service/store;
# the client links no physics (no seep/core header but status.h).
#
# -DSOURCE_DIR=<root> [-DPLANT=<file relative to SOURCE_DIR>|<include path>] — PLANT adds one
# include line to one file in memory, so a test can prove that the check fails on an upward one.
set(rank_base 0)
set(rank_geometry 1)
set(rank_dem 2)
set(rank_flow 2)
set(rank_coupling 3)
set(rank_spec 4)
set(rank_network 5)
set(rank_calibration 6)
set(rank_reference 6)
set(rank_effects 7)
set(rank_run 8)

set(violations "")

# The core folder a path lies in ("base" for the files at the top of include/ or src/).
function(core_area path out)
  if(path MATCHES "core/include/seep/core/([a-z_]+)/")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  elseif(path MATCHES "core/src/([a-z_]+)/")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  else()
    set(${out} base PARENT_SCOPE)
  endif()
endfunction()

function(read_includes file out)
  file(STRINGS ${file} lines REGEX "^#include ")
  if(DEFINED PLANT)
    string(REPLACE "|" ";" plant "${PLANT}")
    list(GET plant 0 plant_file)
    list(GET plant 1 plant_include)
    if(file STREQUAL "${SOURCE_DIR}/${plant_file}")
      list(APPEND lines "#include \"${plant_include}\"")
    endif()
  endif()
  set(${out} "${lines}" PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE core_files ${SOURCE_DIR}/core/*.h ${SOURCE_DIR}/core/*.cc)
foreach(f IN LISTS core_files)
  file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
  core_area(${rel} from)
  if(NOT DEFINED rank_${from})
    list(APPEND violations "${rel}: folder '${from}' has no rank in cmake/LayeringCheck.cmake")
    continue()
  endif()
  read_includes(${f} includes)
  foreach(line IN LISTS includes)
    if(line MATCHES "#include [<\"](google/protobuf|grpc|grpcpp|sqlite3)")
      list(APPEND violations "${rel}: includes ${CMAKE_MATCH_1} (no protobuf, gRPC or SQLite in core)")
      continue()
    endif()
    set(to "")
    if(line MATCHES "#include \"seep/core/([a-z_]+)/")
      set(to ${CMAKE_MATCH_1})
    elseif(line MATCHES "#include \"seep/core/[a-z_]+\\.h\"")
      set(to base)
    elseif(line MATCHES "#include \"\\.\\./([a-z_]+)/")
      set(to ${CMAKE_MATCH_1})
    elseif(line MATCHES "#include \"\\.\\./[a-z_]+\\.h\"")
      set(to base)
    endif()
    if(to STREQUAL "" OR to STREQUAL from)
      continue()
    endif()
    if(NOT DEFINED rank_${to})
      list(APPEND violations "${rel}: includes folder '${to}', which has no rank")
    elseif(NOT rank_${to} LESS rank_${from})
      list(APPEND violations
           "${rel}: ${from} (rank ${rank_${from}}) includes ${to} (rank ${rank_${to}}): ${line}")
    endif()
  endforeach()
endforeach()

# Adds a violation for every include matching `bad` (and not `allowed`) in the files of `folder`
# whose path does not match `exempt`.
function(forbid_includes folder exempt bad allowed why)
  file(GLOB_RECURSE files ${SOURCE_DIR}/${folder}/*.h ${SOURCE_DIR}/${folder}/*.cc)
  foreach(f IN LISTS files)
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
    if(NOT exempt STREQUAL "" AND rel MATCHES "${exempt}")
      continue()
    endif()
    read_includes(${f} includes)
    foreach(line IN LISTS includes)
      if(line MATCHES "${bad}" AND (allowed STREQUAL "" OR NOT line MATCHES "${allowed}"))
        list(APPEND violations "${rel}: ${why}: ${line}")
      endif()
    endforeach()
  endforeach()
  set(violations "${violations}" PARENT_SCOPE)
endfunction()

forbid_includes(service "^service/store/" "#include [<\"]sqlite3\\.h" "" "SQLite outside service/store")
forbid_includes(client "" "#include \"seep/core/" "seep/core/status\\.h" "the client includes physics")

list(LENGTH core_files n)
if(violations)
  string(REPLACE ";" "\n  " lines "${violations}")
  message(FATAL_ERROR "layering: includes that cross the layers the wrong way:\n  ${lines}")
endif()
message(STATUS "layering: ${n} core files, every include points down")
