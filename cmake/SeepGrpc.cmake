# gRPC from Debian 12: prefer the CMake package config, fall back to pkg-config where the config
# is missing or broken (grpc/grpc#29977, #38838). Defines gRPC::grpc++, gRPC::grpc++_reflection
# and SEEP_GRPC_CPP_PLUGIN.
find_package(gRPC CONFIG QUIET)
if(TARGET gRPC::grpc++ AND TARGET gRPC::grpc++_reflection)
  message(STATUS "gRPC: CMake config ${gRPC_VERSION}")
else()
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(SEEP_GRPCPP REQUIRED IMPORTED_TARGET grpc++)
  add_library(gRPC::grpc++ INTERFACE IMPORTED)
  target_link_libraries(gRPC::grpc++ INTERFACE PkgConfig::SEEP_GRPCPP)
  find_library(SEEP_GRPCPP_REFLECTION grpc++_reflection REQUIRED)
  add_library(gRPC::grpc++_reflection INTERFACE IMPORTED)
  target_link_libraries(gRPC::grpc++_reflection INTERFACE ${SEEP_GRPCPP_REFLECTION} gRPC::grpc++)
  message(STATUS "gRPC: pkg-config ${SEEP_GRPCPP_VERSION}")
endif()
find_program(SEEP_GRPC_CPP_PLUGIN grpc_cpp_plugin REQUIRED)
