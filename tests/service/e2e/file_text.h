// Files the end-to-end tests read back (results, exports, logs, metrics pages), and the Python
// interpreter their checks run in.
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace seep::testing {

// The whole file as bytes; empty when it cannot be opened (the caller's assertion says which).
inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {(std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()};
}

// The interpreter of the checks written in Python (python3-vtk9 reads the VTK files back).
inline constexpr const char* kPython = "/usr/bin/python3";

}  // namespace seep::testing
