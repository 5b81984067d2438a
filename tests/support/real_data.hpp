// Where the real-data tests find their data: the directory DYNCULL_DATA_DIR names (../shared/data in CI).
// A machine without it skips those tests with the reason; a directory that is there but lacks a file the
// test reads is the test's own business (most fail: the data is incomplete).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace dyncull::test {

/// The real-data directory, or empty with `why_not` saying why a test that needs it skips: the variable
/// is unset or empty, or it names no directory.
inline std::string real_data_dir(std::string* why_not) {
  const char* root = std::getenv("DYNCULL_DATA_DIR");
  if (root == nullptr || *root == '\0') {
    *why_not = "DYNCULL_DATA_DIR is not set (point it at the shared data directory, e.g. ../shared/data)";
    return std::string();
  }
  std::error_code error;
  if (!std::filesystem::is_directory(root, error)) {
    *why_not = std::string("DYNCULL_DATA_DIR names no directory: '") + root +
               "' (point it at the shared data directory, e.g. ../shared/data)";
    return std::string();
  }
  return root;
}

}  // namespace dyncull::test
