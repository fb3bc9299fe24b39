// rotafab-read-mesh PARENT EXTENSION [PATH] < BYTES: reads a mesh file with
// Assimp and writes it back on standard output, for the importer
// (MeshImport.cpp), which runs this program so that Assimp runs in a process
// of its own. PARENT is the importer's process id: this program ends with it.
// The bytes of the file come on standard input; PATH, when given, is where
// they came from, for the files they refer to. The reply is one tag byte, then the
// mesh ('M', MeshWire.h), or one line saying what is wrong with the file ('E'),
// or Assimp's own message on it ('A').
// Exit status 0 whenever a reply was written; anything else is a crash.

#include <fcntl.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "geometry/io/AssimpReader.h"
#include "geometry/io/MeshWire.h"

namespace {

std::string readAll(int fd) {
  std::string bytes;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw std::runtime_error("cannot read the mesh's bytes");
    if (n == 0) return bytes;
    bytes.append(buffer, static_cast<size_t>(n));
  }
}

bool writeAll(int fd, const std::string& bytes) {
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

std::string firstLineOf(const char* text) {
  std::string line = text ? text : "";
  if (const size_t end = line.find('\n'); end != std::string::npos) line.resize(end);
  return line.empty() ? "the file could not be read" : line;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fputs("usage: rotafab-read-mesh PARENT EXTENSION [PATH] < BYTES (run by rotafab, not by people)\n", stderr);
    return 2;
  }
  // Gone with the program that asked: nobody would read the answer. Asked
  // first, then checked: the parent may have gone before the ask.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (std::to_string(::getppid()) != argv[1]) ::_exit(5);
  // The reply on a descriptor of its own; a library's prints go nowhere.
  const int replyTo = ::fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 3);
  if (const int devNull = ::open("/dev/null", O_WRONLY); devNull >= 0) ::dup2(devNull, STDOUT_FILENO);
  if (replyTo < 0) ::_exit(6);
  namespace geo = rotafab::geometry;
  std::string reply;
  try {
    const std::string bytes = readAll(STDIN_FILENO);
    const std::filesystem::path path = argc == 4 ? argv[3] : "";
    reply = "M" + geo::serializeMesh(geo::readWithAssimp(bytes, argv[2], argc == 4 ? &path : nullptr));
  } catch (const geo::InvalidMeshError& error) {
    reply = std::string("E") + error.what();
  } catch (const geo::AssimpFailure& error) {
    reply = std::string("A") + error.what();
  } catch (const std::bad_alloc&) {
    reply = "Ethe mesh does not fit in memory";
  } catch (const std::exception& error) {
    // Assimp throws DeadlyImportError and others on some malformed inputs.
    reply = "A" + firstLineOf(error.what());
  }
  // _exit: no destructors of Assimp's statics, and no leak report of a
  // sanitizer build (Debian's Assimp leaks on some inputs) in the way.
  ::_exit(writeAll(replyTo, reply) ? 0 : 4);
}
