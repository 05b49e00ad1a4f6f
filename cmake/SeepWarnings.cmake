# Warnings for project code only; generated protobuf code gets none (see proto/CMakeLists.txt).
function(seep_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wnon-virtual-dtor
                                           -Woverloaded-virtual -Wimplicit-fallthrough)
  # A unity batch (CMAKE_UNITY_BUILD, what the CI builds) includes each file from a generated
  # one, and GCC then takes a lambda or class that uses the file's anonymous namespace for one
  # visible outside it (-Wsubobject-linkage): true only of a header, never of a batch.
  # GCC 12 at -O3 also reports -Wrestrict and -Wstringop-overflow inside std::string's inlined
  # copies once a batch holds several files that build strings (false positives of GCC 12 at -O3,
  # gone in later GCCs): the same code gives none of them one file a unit, where the two stay on.
  if(CMAKE_UNITY_BUILD)
    target_compile_options(${target} PRIVATE -Wno-subobject-linkage -Wno-restrict
                                             -Wno-stringop-overflow)
  endif()
  if(SEEP_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
