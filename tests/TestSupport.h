#pragma once
// Small helpers shared by the test suites: temporary folders and files,
// running the built `rotafab` program, and topology in one call.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "geometry/MeshAnalysis.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::test {

class TempDir {
 public:
  TempDir() {
    std::random_device random;
    path_ = std::filesystem::temp_directory_path() / ("rotafab-test-" + std::to_string(random()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    const auto file = path_ / name;
    std::ofstream(file, std::ios::binary) << bytes;
    return file;
  }

 private:
  std::filesystem::path path_;
};

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CommandResult {
  int status = -1;
  std::string out;
  std::string err;
};

// Runs a shell command line, capturing standard output and error.
inline CommandResult run(const std::string& commandLine) {
  TempDir scratch;
  const auto outFile = scratch.path() / "out", errFile = scratch.path() / "err";
  const std::string full = commandLine + " >" + outFile.string() + " 2>" + errFile.string() + " </dev/null";
  const int raw = std::system(full.c_str());
  CommandResult result;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  result.out = readFile(outFile);
  result.err = readFile(errFile);
  return result;
}

inline geometry::MeshTopology topologyOf(geometry::PolygonMesh mesh) { return geometry::analyzeMesh(mesh).topology; }

}  // namespace rotafab::test
