// tests/support/temp_dir.hpp: a fresh directory under the system temp dir, removed with its
// contents when the object goes out of scope. Tests write files only here.
#pragma once
#include <filesystem>
#include <random>
#include <string>
#include <system_error>
#include <vector>

namespace fesd::testing {

class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "fesd_test") {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            (prefix + "_" + std::to_string(rd()) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// Path of `name` inside the directory (the file is not created).
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// Names of the directory's entries.
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(path_))
      out.push_back(e.path().filename().string());
    return out;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace fesd::testing
