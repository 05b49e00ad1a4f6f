# Warnings for project code only; generated protobuf code gets none (see proto/CMakeLists.txt).
function(seep_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wnon-virtual-dtor
                                           -Woverloaded-virtual -Wimplicit-fallthrough)
  if(SEEP_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
