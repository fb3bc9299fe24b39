#pragma once
// Small helpers shared by the test suites: temporary folders and files,
// running a program, and the meshes other people made that Debian packages
// install.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace rotafab::test {

// How much longer than in the product a promised delay ("stops within a
// second") may take in this build: AddressSanitizer's allocator frees the
// memory of a stopped job several times slower, and its leak check runs at
// exit, so the sanitizer build checks the same promise on a scaled clock.
#ifdef ROTAFAB_SANITIZED
inline constexpr double kPromisedDelayScale = 4.0;
#else
inline constexpr double kPromisedDelayScale = 1.0;
#endif

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

// A path in single quotes, for the shell. (Built by appending: GCC 12 warns
// falsely, -Wrestrict, on "'" + std::string.)
inline std::string quoted(const std::filesystem::path& path) {
  std::string text = "'";
  text += path.string();
  text += '\'';
  return text;
}

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

// A mesh that someone else made, as a Debian package of scripts/setup.sh
// installs it (tests/data/external/README.md): a plain path, or
// "ARCHIVE.tar.gz:MEMBER" for a file inside a tarball (CGAL's data sets),
// extracted once per test program into a folder that lives as long as it.
inline std::filesystem::path publicMesh(const std::string& where) {
  const auto colon = where.find(".tar.gz:");
  if (colon == std::string::npos) {
    EXPECT_TRUE(std::filesystem::exists(where)) << where << ": install it with scripts/setup.sh";
    return where;
  }
  static TempDir extracted;
  const std::string archive = where.substr(0, colon + 7), member = where.substr(colon + 8);
  const auto path = extracted.path() / member;
  if (!std::filesystem::exists(path)) {
    const CommandResult untar =
        run("tar -xzf '" + archive + "' -C '" + extracted.path().string() + "' '" + member + "'");
    EXPECT_EQ(untar.status, 0) << where << ": " << untar.err << " (install it with scripts/setup.sh)";
  }
  return path;
}

// CGAL's data sets (Debian package libcgal-demo).
inline std::string cgalMesh(const std::string& name) {
  return "/usr/share/doc/libcgal-dev/data.tar.gz:data/meshes/" + name;
}

}  // namespace rotafab::test
