#pragma once
// Lines over a socket (a helper process's standard input and output): reads
// with a timeout, writes whole lines from any thread, never a SIGPIPE when
// the other side is gone.

#include <chrono>
#include <mutex>
#include <optional>
#include <string>

namespace rotafab::devices::remote {

class LinePipe {
 public:
  // Takes the two descriptors of a socket, to read from and to write to
  // (closed by the destructor unless `own` is false).
  LinePipe(int readFd, int writeFd, bool own = true);
  ~LinePipe();
  LinePipe(const LinePipe&) = delete;
  LinePipe& operator=(const LinePipe&) = delete;

  enum class Read { Line, Timeout, End };
  // The next line (without its newline) into `line`, or Timeout, or End when
  // the other side has closed its end (or gone).
  Read readLine(std::string& line, std::chrono::milliseconds timeout);
  // False when the other side is gone.
  bool writeLine(const std::string& line);
  void closeWrite();

 private:
  int read_, write_;
  bool own_;
  std::string buffer_;
  std::mutex writing_;
};

}  // namespace rotafab::devices::remote
