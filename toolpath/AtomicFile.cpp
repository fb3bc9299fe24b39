#include "toolpath/AtomicFile.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rotafab::jobs {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, std::string_view what, int error) {
  throw std::runtime_error(fmt::format("cannot write {}: {}: {}", path.string(), what, std::strerror(error)));
}

// Creates a new, empty temporary file beside `path`; returns its descriptor
// and sets `temporary` to its name. Names are random so that concurrent
// writers of the same target never share a temporary file.
int createTemporary(const std::filesystem::path& path, std::filesystem::path& temporary) {
  std::random_device seed;
  std::mt19937_64 random((static_cast<uint64_t>(seed()) << 32) ^ seed() ^ static_cast<uint64_t>(getpid()));
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  for (int attempt = 0; attempt < 100; ++attempt) {
    temporary = folder / fmt::format(".{}.tmp-{:016x}", path.filename().string(), random());
    const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    if (errno != EEXIST) fail(path, "cannot create a temporary file in " + folder.string(), errno);
  }
  fail(path, "cannot find a free temporary file name", EEXIST);
}

// Best effort: makes the rename itself durable. The target is complete
// whether or not this succeeds, so a failure here is not reported.
void syncFolder(const std::filesystem::path& path) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
  if (path.filename().empty()) fail(path, "not a file name", EISDIR);
  std::filesystem::path temporary;
  int fd = createTemporary(path, temporary);
  auto abandon = [&](std::string_view what) {
    const int error = errno;
    if (fd >= 0) ::close(fd);
    ::unlink(temporary.c_str());
    fail(path, what, error);
  };

  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      abandon("write failed");
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) abandon("fsync failed");
  const int closing = fd;
  fd = -1;
  if (::close(closing) != 0) abandon("close failed");
  if (::rename(temporary.c_str(), path.c_str()) != 0) abandon("rename failed");
  syncFolder(path);
}

void writeFileAtomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write) {
  std::ostringstream content;
  write(content);
  if (!content) throw std::runtime_error(fmt::format("cannot write {}: formatting the content failed", path.string()));
  writeFileAtomically(path, content.view());
}

}  // namespace rotafab::jobs
