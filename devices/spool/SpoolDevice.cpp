#include "devices/spool/SpoolDevice.h"

#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <fstream>
#include <sstream>

#include "toolpath/AtomicFile.h"
#include "toolpath/EpsWriter.h"

extern char** environ;

namespace rotafab::devices::spool {

jobs::SheetDrawing drawingOf(const jobs::Toolpath& toolpath, const std::map<jobs::Operation, jobs::Rgb>& colours) {
  jobs::SheetDrawing sheet;
  sheet.index = toolpath.sheet;
  sheet.width = toolpath.width, sheet.height = toolpath.height, sheet.margin = 0;
  sheet.colours = colours;
  sheet.title = fmt::format("rotafab sheet {}", toolpath.sheet);
  for (const jobs::ToolpathStroke& stroke : toolpath.strokes) {
    if (stroke.pass != 1) continue;
    jobs::DrawnPath path{stroke.operation, stroke.points, false};
    if (path.points.size() > 2 && path.points.front() == path.points.back()) {
      path.points.pop_back();
      path.closed = true;
    }
    sheet.paths.push_back(std::move(path));
  }
  return sheet;
}

SpoolDevice::SpoolDevice(std::filesystem::path folder, std::string printer,
                         std::map<jobs::Operation, jobs::Rgb> colours)
    : folder_(std::move(folder)), printer_(std::move(printer)), colours_(std::move(colours)) {}

std::string SpoolDevice::connect() {
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  if (error || !std::filesystem::is_directory(folder_)) {
    throw DeviceFault(FaultKind::Disconnected, fmt::format("spool:{}: cannot make the folder: {}", folder_.string(),
                                                           error ? error.message() : "not a folder"));
  }
  return printer_.empty() ? fmt::format("EPS files in {}", folder_.string())
                          : fmt::format("EPS files in {}, printed on {} with lp", folder_.string(), printer_);
}

void SpoolDevice::run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
                      const core::Cancellation& cancel) {
  if (cancel.cancelled()) throw DeviceFault(FaultKind::Cancelled, "spool: cancelled");
  const jobs::SheetDrawing sheet = drawingOf(toolpath, colours_);
  const std::filesystem::path eps = folder_ / fmt::format("sheet-{:03}.eps", toolpath.sheet);
  try {
    jobs::writeFileAtomically(eps, [&](std::ostream& out) { jobs::writeEps(sheet, out); });
  } catch (const std::exception& error) {
    throw DeviceFault(FaultKind::Disconnected, fmt::format("spool:{}: {}", folder_.string(), error.what()));
  }
  if (!printer_.empty()) {
    // lp -d PRINTER -t TITLE -- FILE, without a shell (a file named "-x" is no option).
    const std::string title = sheet.title, file = eps.string();
    std::vector<std::string> args{"lp", "-d", printer_, "-t", title, "--", file};
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    // lp with the signals as a program started from the shell has them (the
    // command line blocks SIGINT and SIGTERM for its own watcher): Ctrl-C
    // reaches it.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t none, defaults;
    sigemptyset(&none);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigmask(&attributes, &none);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, "lp", nullptr, &attributes, argv.data(), environ);
    posix_spawnattr_destroy(&attributes);
    // (lp never ran, or refused the file: nothing reached the printer queue)
    const auto notSent = [](FaultKind kind, const std::string& what) {
      DeviceFault fault(kind, what);
      fault.nothingSent = true;
      return fault;
    };
    if (spawned != 0) throw notSent(FaultKind::Disconnected, "spool: cannot run lp (install cups-client)");
    int status = 0;
    pid_t waited = 0;
    do {
      waited = waitpid(pid, &status, 0);
    } while (waited < 0 && errno == EINTR);
    if (cancel.cancelled()) throw DeviceFault(FaultKind::Cancelled, "spool: cancelled");
    if (waited != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      throw notSent(FaultKind::Refused, fmt::format("spool: lp -d {} refused {} (exit status {})", printer_, file,
                                                    WIFEXITED(status) ? WEXITSTATUS(status) : -1));
    }
  }
  if (progress) {
    Progress done;
    done.sheet = toolpath.sheet;
    done.stroke = done.strokes = done.strokesCut = toolpath.strokes.size();
    done.bytesAcknowledged = done.bytesTotal = std::filesystem::file_size(eps);
    progress(done);
  }
}

std::string SpoolDevice::program(const std::vector<jobs::Toolpath>& toolpaths) const {
  std::ostringstream out;
  for (const jobs::Toolpath& toolpath : toolpaths) jobs::writeEps(drawingOf(toolpath, colours_), out);
  return out.str();
}

std::string SpoolDevice::describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const {
  return fmt::format("EPS for {} sheet{}, as the spool would write it", toolpaths.size(),
                     toolpaths.size() == 1 ? "" : "s");
}

}  // namespace rotafab::devices::spool
