#include "devices/remote/LinePipe.h"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>

namespace rotafab::devices::remote {

LinePipe::LinePipe(int readFd, int writeFd, bool own) : read_(readFd), write_(writeFd), own_(own) {}

LinePipe::~LinePipe() {
  if (!own_) return;
  if (read_ >= 0) ::close(read_);
  if (write_ >= 0) ::close(write_);
}

LinePipe::Read LinePipe::readLine(std::string& line, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (const auto newline = buffer_.find('\n'); newline != std::string::npos) {
      line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      return Read::Line;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return Read::Timeout;
    pollfd waiting{read_, POLLIN, 0};
    const int ready = ::poll(&waiting, 1, static_cast<int>(left));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    char bytes[4096];
    const ssize_t n = ::read(read_, bytes, sizeof bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Read::End;
    buffer_.append(bytes, static_cast<size_t>(n));
  }
}

bool LinePipe::writeLine(const std::string& line) {
  const std::lock_guard lock(writing_);
  if (write_ < 0) return false;
  const std::string bytes = line + "\n";
  size_t written = 0;
  while (written < bytes.size()) {
    // A socket (as the helper's is): no SIGPIPE when the other side is gone.
    const ssize_t n = ::send(write_, bytes.data() + written, bytes.size() - written, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

void LinePipe::closeWrite() {
  const std::lock_guard lock(writing_);
  if (write_ >= 0 && own_) ::close(write_);
  write_ = -1;
}

}  // namespace rotafab::devices::remote
