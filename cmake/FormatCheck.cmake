# Fails when any C++ file under the source tree is not clang-formatted (generated code excluded).
file(GLOB_RECURSE files
     ${SOURCE_DIR}/core/*.h ${SOURCE_DIR}/core/*.cc ${SOURCE_DIR}/service/*.h
     ${SOURCE_DIR}/service/*.cc ${SOURCE_DIR}/client/*.h ${SOURCE_DIR}/client/*.cc
     ${SOURCE_DIR}/tests/*.h ${SOURCE_DIR}/tests/*.cc ${SOURCE_DIR}/bench/*.h
     ${SOURCE_DIR}/bench/*.cc)
set(bad "")
foreach(f IN LISTS files)
  execute_process(COMMAND ${CLANG_FORMAT} --dry-run --Werror --style=file ${f}
                  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 0)
    list(APPEND bad ${f})
  endif()
endforeach()
list(LENGTH files n)
if(bad)
  string(REPLACE ";" "\n  " bad_lines "${bad}")
  message(FATAL_ERROR "clang-format: these files need formatting (run clang-format -i):\n  ${bad_lines}")
endif()
message(STATUS "clang-format: ${n} files clean")
