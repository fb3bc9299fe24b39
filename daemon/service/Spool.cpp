#include "daemon/service/Spool.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <stdexcept>
#include <system_error>

namespace rotafab::service {
namespace fs = std::filesystem;
namespace {

std::string randomName() {
  static thread_local std::mt19937_64 generator{std::random_device{}()};
  return fmt::format("{:016x}", generator());
}

}  // namespace

void syncFolder(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    throw std::runtime_error(fmt::format("{}: cannot open the folder: {}", folder.string(), std::strerror(errno)));
  const int synced = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (synced != 0) {
    throw std::runtime_error(fmt::format("{}: cannot sync the folder: {}", folder.string(), std::strerror(error)));
  }
}

Spool::Spool(fs::path folder, std::string owner) : folder_(std::move(folder)), owner_(std::move(owner)) {
  std::error_code error;
  fs::create_directories(folder_, error);
  if (error)
    throw std::runtime_error(fmt::format("{}: cannot create the spool: {}", folder_.string(), error.message()));
}

Spool::Entry Spool::begin() const {
  const std::string name = "job-" + randomName() + (owner_.empty() ? "" : "@" + owner_);
  fs::path folder = folder_ / name;
  std::error_code error;
  fs::create_directory(folder, error);
  if (error) {
    throw std::runtime_error(fmt::format("{}: cannot create a spool entry: {}", folder.string(), error.message()));
  }
  return Entry(*this, std::move(folder), name);
}

Spool::Entry::Entry(const Spool& spool, fs::path folder, std::string name)
    : spool_(&spool), folder_(std::move(folder)), name_(std::move(name)) {}

Spool::Entry::Entry(Entry&& other) noexcept
    : spool_(other.spool_),
      folder_(std::move(other.folder_)),
      name_(std::move(other.name_)),
      committed_(other.committed_) {
  other.committed_ = true;  // the moved-from entry removes nothing
}

Spool::Entry::~Entry() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(folder_, ignored);
}

Spool::Entry::File Spool::Entry::create(std::string_view name) {
  fs::path file = folder_ / std::string(name);
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw std::runtime_error(fmt::format("{}: cannot create the file: {}", file.string(), std::strerror(errno)));
  return File(fd, std::move(file));
}

Spool::Entry::File::File(File&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) { other.fd_ = -1; }

Spool::Entry::File::~File() {
  if (fd_ >= 0) ::close(fd_);
}

void Spool::Entry::File::write(std::string_view bytes) {
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw std::runtime_error(
          fmt::format("{}: cannot write the file: {}", path_.string(), std::strerror(n < 0 ? errno : ENOSPC)));
    }
    written += static_cast<size_t>(n);
  }
}

void Spool::Entry::File::close() {
  const int fd = fd_;
  fd_ = -1;
  if (fd >= 0 && ::close(fd) != 0) {
    throw std::runtime_error(fmt::format("{}: cannot write the file: {}", path_.string(), std::strerror(errno)));
  }
}

void Spool::Entry::addFile(std::string_view name, std::string_view bytes) {
  File file = create(name);
  file.write(bytes);
  file.close();
}

void Spool::Entry::copyFile(std::string_view name, const fs::path& from) {
  const int in = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0)
    throw std::runtime_error(fmt::format("{}: cannot read the file: {}", from.string(), std::strerror(errno)));
  struct Closed {
    int fd;
    ~Closed() { ::close(fd); }
  } closed{in};
  File file = create(name);
  std::string buffer(1 << 16, '\0');
  for (;;) {
    const ssize_t n = ::read(in, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw std::runtime_error(fmt::format("{}: cannot read the file: {}", from.string(), std::strerror(errno)));
    if (n == 0) break;
    file.write(std::string_view(buffer.data(), static_cast<size_t>(n)));
  }
  file.close();
}

void Spool::Entry::addFolder(const fs::path& from) {
  std::error_code error;
  for (const fs::directory_entry& file : fs::directory_iterator(from, error)) {
    if (!file.is_regular_file()) continue;
    const fs::path target = folder_ / file.path().filename();
    if (::link(file.path().c_str(), target.c_str()) == 0) continue;
    // Another file system, or a file the daemon may not link: a copy.
    copyFile(file.path().filename().string(), file.path());
  }
  if (error) throw std::runtime_error(fmt::format("{}: cannot read the folder: {}", from.string(), error.message()));
}

void Spool::Entry::commitAll(const std::vector<Entry*>& entries) {
  if (entries.empty()) return;
  entries.front()->commit();
  for (Entry* entry : entries) entry->committed_ = true;
}

std::string Spool::Entry::commit() {
  const int fd = ::open(folder_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot open the spool entry: {}", folder_.string(), std::strerror(errno)));
  }
  const int synced = ::syncfs(fd);
  const int error = errno;
  ::close(fd);
  if (synced != 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot sync the spool entry: {}", folder_.string(), std::strerror(error)));
  }
  committed_ = true;
  return name_;
}

size_t Spool::removeOrphans(const std::set<std::string>& named) const {
  size_t removed = 0;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder_, error)) {
    const std::string name = entry.path().filename().string();
    if (named.contains(name)) continue;
    if (!name.starts_with("job-")) continue;
    if (!owner_.empty() && !name.ends_with("@" + owner_)) continue;  // another host's, perhaps being filled now
    std::error_code ignored;
    fs::remove_all(entry.path(), ignored);
    ++removed;
  }
  return removed;
}

}  // namespace rotafab::service
