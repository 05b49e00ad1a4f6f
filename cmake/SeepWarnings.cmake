# Warnings for project code only; generated protobuf code gets none (see proto/CMakeLists.txt).
function(seep_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wnon-virtual-dtor
                                           -Woverloaded-virtual -Wimplicit-fallthrough)
  # A unity batch (CMAKE_UNITY_BUILD, what the CI builds) includes each file from a generated
  # one, and GCC then takes a lambda or class that uses the file's anonymous namespace for one
  # visible outside it (-Wsubobject-linkage): true only of a header, never of a batch.
  if(CMAKE_UNITY_BUILD)
    target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
  endif()
  if(SEEP_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
