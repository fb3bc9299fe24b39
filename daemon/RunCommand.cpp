#include "daemon/RunCommand.h"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "daemon/CommandSupport.h"
#include "daemon/ExitCode.h"
#include "devices/DeviceUri.h"
#include "devices/Discovery.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/m2nano/Lhymicro.h"
#include "devices/sim/M2NanoSimulator.h"
#include "devices/spool/SpoolDevice.h"
#include "jobs/AtomicFile.h"
#include "jobs/EpsWriter.h"
#include "jobs/GCode.h"
#include "jobs/SheetReader.h"
#include "jobs/Toolpath.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {
namespace {

struct RunOptions {
  std::string target, device, out, machine, material = "posterboard";
  std::optional<int> sheet;
  bool frame = false, dryRun = false, json = false;
};

// Ctrl-C: the running job is cancelled (the driver holds, resets and turns the laser off).
devices::CancelFlag* interruptFlag = nullptr;
extern "C" void onInterrupt(int) {
  if (interruptFlag) interruptFlag->cancel();
}

// The sheets to run: (number, SVG file).
std::vector<std::pair<int, std::filesystem::path>> sheetsOf(const RunOptions& options) {
  const std::filesystem::path target(options.target);
  std::vector<std::pair<int, std::filesystem::path>> sheets;
  if (std::filesystem::is_directory(target)) {
    const auto manifestFile = target / "manifest.json";
    std::ifstream in(manifestFile);
    if (!in)
      throw UserError(fmt::format("{}: no manifest.json (is it an output folder of `rotafab make`?)", target.string()));
    nlohmann::json manifest;
    try {
      manifest = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& error) {
      throw UserError(fmt::format("{}: not JSON: {}", manifestFile.string(), error.what()));
    }
    try {
      for (const auto& sheet : manifest.at("sheets")) {
        const int index = sheet.at("index");
        for (const auto& file : sheet.at("files")) {
          const std::string name = file;
          if (name.ends_with(".svg")) sheets.emplace_back(index, target / name);
        }
      }
    } catch (const nlohmann::json::exception& error) {
      throw UserError(fmt::format("{}: sheets: {}", manifestFile.string(), error.what()));
    }
    if (sheets.empty()) throw UserError(fmt::format("{}: lists no SVG sheet", manifestFile.string()));
  } else {
    if (target.extension() != ".svg") {
      throw UserError(
          fmt::format("{}: give the sheet's .svg (or the output folder of `rotafab make`)", target.string()));
    }
    sheets.emplace_back(1, target);
  }
  if (options.sheet) {
    const auto it =
        std::find_if(sheets.begin(), sheets.end(), [&](const auto& s) { return s.first == *options.sheet; });
    if (it == sheets.end()) {
      throw UserError(fmt::format("--sheet {}: {} has sheets 1 to {}", *options.sheet, options.target, sheets.size()));
    }
    sheets = {*it};
  }
  return sheets;
}

// Waits for a line on standard input while watching for Ctrl-C (a read
// restarted after the signal would not see it). False on a cancel or the end of input.
bool waitForEnter(const devices::CancelFlag& cancel) {
  for (;;) {
    if (cancel.cancelled()) return false;
    pollfd input{STDIN_FILENO, POLLIN, 0};
    if (::poll(&input, 1, 200) > 0) {
      char byte = 0;
      while (::read(STDIN_FILENO, &byte, 1) == 1) {
        if (byte == '\n') return true;
      }
      return false;
    }
  }
}

std::string minutes(double seconds) {
  const int s = static_cast<int>(std::lround(seconds));
  return s >= 60 ? fmt::format("{}m {:02}s", s / 60, s % 60) : fmt::format("{}s", s);
}

int runRun(const RunOptions& options, char** argv) {
  return reportingErrors(options.target, [&]() -> int {
    try {
      const devices::DeviceUri uri = [&] {
        try {
          return devices::parseDeviceUri(options.device);
        } catch (const std::invalid_argument& error) {
          throw UserError(error.what());
        }
      }();
      if (uri.driver == "m2nano" && uri.transport == "sim" && !options.dryRun) {
        // The simulated board is plugged in through umockdev's preloaded
        // library: the program starts again with it (before it has done anything).
        try {
          devices::sim::runUnderUmockdev(argv);
        } catch (const std::runtime_error& error) {
          throw UserError(fmt::format("--device {}: {}", options.device, error.what()));
        }
      }
      if (options.dryRun && options.out.empty()) throw UserError("--dry-run needs --out FILE: where the bytes go");
      const auto sheets = sheetsOf(options);
      const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
      profiles::MachineProfile machine;
      if (!options.machine.empty()) {
        machine = profiles::findMachine(catalogue, options.machine);
      } else {
        const auto it = std::find_if(catalogue.machines.begin(), catalogue.machines.end(),
                                     [&](const auto& m) { return m.driver == uri.driver; });
        if (it == catalogue.machines.end())
          throw UserError(fmt::format("no machine profile for the {} driver; give --machine", uri.driver));
        machine = *it;
      }
      if (machine.driver != uri.driver) {
        throw UserError(fmt::format("--machine {} is driven by {}, not by --device {}'s {} driver", machine.name,
                                    machine.driver, options.device, uri.driver));
      }
      const profiles::MaterialProfile material = profiles::findMaterial(catalogue, options.material);
      std::vector<jobs::SheetDrawing> drawings;
      for (const auto& [index, file] : sheets) {
        try {
          drawings.push_back(jobs::readSheetSvg(file));
        } catch (const std::invalid_argument& error) {
          throw UserError(error.what());
        }
        const jobs::SheetDrawing& sheet = drawings.back();
        if (sheet.width > machine.bed.width + 1e-6 || sheet.height > machine.bed.height + 1e-6) {
          throw UserError(
              fmt::format("{}: the sheet is {:.4g} x {:.4g} in, larger than the bed of {} ({:.4g} x {:.4g} in); "
                          "make it for this machine (`rotafab make ... --machine {}`)",
                          file.string(), sheet.width, sheet.height, machine.name, machine.bed.width, machine.bed.height,
                          machine.name));
        }
      }

      // A dry run opens no real port: S and F follow GRBL's defaults ($30=1000,
      // $110=500 mm/min) unless the device is the simulator, which it asks.
      std::unique_ptr<devices::Device> device;
      jobs::GCodeOptions gcode;
      jobs::MotionLimits limits;
      std::string identity;
      std::map<jobs::Operation, jobs::Rgb> colours;
      for (profiles::Operation operation : profiles::kAllOperations)
        colours[operation] = machine.settingFor(operation).rgb;
      if (uri.driver == "m2nano") limits = devices::m2nano::motionLimits();
      if (!options.dryRun || (uri.transport == "sim" && uri.driver == "grbl")) {
        device = devices::openDevice(uri, colours);
        identity = device->connect();
        if (auto* grbl = dynamic_cast<devices::grbl::GrblDriver*>(device.get())) {
          gcode = grbl->gcodeOptions();
          limits = grbl->motionLimits();
        }
        fmt::print(stderr, "run: {}: {}\n", options.device, identity);
      } else {
        if (uri.driver == "grbl") {
          fmt::print(stderr, "run: dry run: S and F for GRBL's default settings ($30=1000, $110=500 mm/min)\n");
        }
      }

      std::vector<jobs::Toolpath> toolpaths;
      for (const jobs::SheetDrawing& sheet : drawings) {
        try {
          toolpaths.push_back(jobs::planToolpath(sheet, machine, material, limits));
        } catch (const std::invalid_argument& error) {
          throw UserError(error.what());
        }
      }
      if (options.dryRun && toolpaths.size() > 1) {
        // One file of several sheets would be cut back to back, onto one sheet.
        throw UserError(fmt::format("{}: {} sheets: a dry run writes one sheet's job; give --sheet N", options.target,
                                    toolpaths.size()));
      }
      if (options.dryRun && uri.driver == "m2nano") {
        // The LHYMICRO-GL the board would get, as an .egv file (SPEC, "Devices").
        std::vector<std::string> lines;
        for (const jobs::Toolpath& toolpath : toolpaths) {
          const auto sheet = devices::m2nano::jobLines(toolpath);
          lines.insert(lines.end(), sheet.begin(), sheet.end());
        }
        jobs::writeFileAtomically(options.out, devices::m2nano::egvFile(lines));
        fmt::print("{}: LHYMICRO-GL for {} sheet{} (an .egv file K40 Whisperer and MeerK40t open)\n", options.out,
                   toolpaths.size(), toolpaths.size() == 1 ? "" : "s");
        return kSuccess;
      }
      if (options.dryRun && uri.driver == "spool") {
        // The bytes the spool writes: each sheet's EPS, one after another.
        jobs::writeFileAtomically(options.out, [&](std::ostream& out) {
          for (const jobs::Toolpath& toolpath : toolpaths)
            jobs::writeEps(devices::spool::drawingOf(toolpath, colours), out);
        });
        fmt::print("{}: EPS for {} sheet{}, as the spool would write it\n", options.out, toolpaths.size(),
                   toolpaths.size() == 1 ? "" : "s");
        return kSuccess;
      }
      if (options.dryRun) {
        jobs::writeFileAtomically(options.out, [&](std::ostream& out) {
          for (const jobs::Toolpath& toolpath : toolpaths) {
            for (const std::string& line : jobs::gcodeLines(toolpath, gcode)) out << line << '\n';
          }
        });
        fmt::print("{}: G-code for {} sheet{} ({} strokes), as the driver would send it\n", options.out,
                   toolpaths.size(), toolpaths.size() == 1 ? "" : "s", [&] {
                     size_t n = 0;
                     for (const auto& t : toolpaths) n += t.strokes.size();
                     return n;
                   }());
        return kSuccess;
      }

      if (toolpaths.size() > 1 && !::isatty(STDIN_FILENO)) {
        throw UserError(
            fmt::format("{}: {} sheets, and no terminal to ask before each one that the next is loaded: "
                        "run them one at a time with --sheet N",
                        options.target, toolpaths.size()));
      }
      devices::CancelFlag cancel;
      // Ctrl-C and SIGTERM cancel the job while it runs; the old handlers come back after.
      struct InterruptGuard {
        struct sigaction oldInt {
        }, oldTerm{};
        explicit InterruptGuard(devices::CancelFlag& flag) {
          interruptFlag = &flag;
          struct sigaction action {};
          action.sa_handler = onInterrupt;
          action.sa_flags = SA_RESTART;
          sigaction(SIGINT, &action, &oldInt);
          sigaction(SIGTERM, &action, &oldTerm);
        }
        ~InterruptGuard() {
          sigaction(SIGINT, &oldInt, nullptr);
          sigaction(SIGTERM, &oldTerm, nullptr);
          interruptFlag = nullptr;
        }
      } guard(cancel);
      const bool terminal = ::isatty(STDERR_FILENO) != 0;
      double burnt = 0, seconds = 0;
      size_t strokes = 0;
      const auto started = std::chrono::steady_clock::now();
      try {
        for (size_t s = 0; s < toolpaths.size(); ++s) {
          const jobs::Toolpath& toolpath = toolpaths[s];
          if (s > 0) {
            if (::isatty(STDIN_FILENO)) {
              fmt::print(stderr, "run: load sheet {} and press Enter (Ctrl-C stops)\n", toolpath.sheet);
              if (!waitForEnter(cancel)) cancel.cancel();  // Ctrl-C or end of input: stop, do not cut blind
            }
          }
          if (cancel.cancelled())
            throw devices::DeviceFault(devices::FaultKind::Cancelled, options.device + ": cancelled");
          fmt::print(stderr, "run: sheet {} ({} of {}): {} strokes, {:.1f} in to burn, about {}\n", toolpath.sheet,
                     s + 1, toolpaths.size(), toolpath.strokes.size(), toolpath.burnLength, minutes(toolpath.seconds));
          if (options.frame) {
            fmt::print(stderr, "run: framing (laser off)\n");
            device->frame(toolpath);
          }
          auto lastShown = std::chrono::steady_clock::time_point{};
          int lastPercent = -1;
          device->run(
              toolpath,
              [&](const devices::Progress& p) {
                const int percent = static_cast<int>(100 * p.bytesAcknowledged / std::max<size_t>(p.bytesTotal, 1));
                const auto now = std::chrono::steady_clock::now();
                if (terminal ? now - lastShown < std::chrono::milliseconds(200) && percent != 100
                             : percent / 10 == lastPercent / 10) {
                  return;
                }
                lastShown = now, lastPercent = percent;
                const int filled = percent / 5;
                fmt::print(stderr, "{}run: sheet {} [{}{}] {:3}%  stroke {} of {}, {} left{}", terminal ? "\r" : "",
                           p.sheet, std::string(filled, '#'), std::string(20 - filled, '.'), percent, p.stroke,
                           p.strokes, minutes(p.secondsLeft), terminal ? "" : "\n");
              },
              cancel);
          if (terminal) fmt::print(stderr, "\n");
          burnt += toolpath.burnLength, seconds += toolpath.seconds, strokes += toolpath.strokes.size();
        }
      } catch (const devices::DeviceFault& fault) {
        if (terminal) fmt::print(stderr, "\n");
        fmt::print(stderr, "error: {} ({}; {})\n", fault.what(), devices::faultName(fault.kind),
                   fault.laserOffConfirmed
                       ? "the laser is off"
                       : "the controller did not confirm the laser off: switch it off at the machine");
        return kDeviceFault;
      }
      device->disconnect();
      fmt::print("{}: {} sheet{} cut on {}: {} strokes, {:.1f} in burnt, in {} (estimated {})\n", options.target,
                 toolpaths.size(), toolpaths.size() == 1 ? "" : "s", options.device, strokes, burnt,
                 minutes(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()),
                 minutes(seconds));
      return kSuccess;
    } catch (const devices::DeviceFault& fault) {
      fmt::print(stderr, "error: {} ({})\n", fault.what(), devices::faultName(fault.kind));
      return kDeviceFault;
    }
  });
}

int runDevices(bool json) {
  const auto found = devices::findDevices();
  if (json) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const auto& d : found) {
      nlohmann::ordered_json entry = {{"port", d.port}, {"description", d.description}};
      if (d.vendor >= 0) {
        entry["usb"] = {{"vendor", fmt::format("{:04x}", d.vendor)}, {"product", fmt::format("{:04x}", d.product)}};
        if (!d.serial.empty()) entry["usb"]["serial"] = d.serial;
      }
      entry["driver"] = d.driver.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(d.driver);
      entry["uri"] = d.uri.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(d.uri);
      list.push_back(entry);
    }
    std::cout << list.dump() << '\n';
    return kSuccess;
  }
  if (found.empty()) {
    fmt::print(
        "no serial port or cutter found (a GRBL board shows as /dev/ttyUSB* or /dev/ttyACM*; check the cable, "
        "and that you may open it: the dialout group)\n");
    return kSuccess;
  }
  for (const auto& d : found) {
    fmt::print("{}  {}", d.port, d.description.empty() ? "(no description)" : d.description);
    if (d.vendor >= 0) fmt::print("  usb {:04x}:{:04x}", d.vendor, d.product);
    if (!d.serial.empty()) fmt::print(" serial {}", d.serial);
    if (!d.uri.empty()) fmt::print("\n    {} driver: --device {}", d.driver, d.uri);
    fmt::print("\n");
  }
  return kSuccess;
}

}  // namespace

void addRunCommand(CLI::App& app, int& status, char** argv) {
  auto json = std::make_shared<bool>(false);
  CLI::App* devicesCommand =
      app.add_subcommand("devices", "List the serial ports and cutters plugged in, and the driver for each");
  devicesCommand->add_flag("--json", *json,
                           "Print one JSON array: port, description, usb {vendor, product, serial}, driver, uri");
  devicesCommand->callback([json, &status] { status = runDevices(*json); });

  auto options = std::make_shared<RunOptions>();
  CLI::App* run = app.add_subcommand("run", "Drive a cutter directly: cut the sheets of a `make` output");
  run->add_option("TARGET", options->target, "An output folder of `rotafab make`, or one sheet's .svg")->required();
  run->add_option("--device", options->device,
                  "Device URI: grbl:///dev/ttyUSB0?baud=115200, grbl+tcp://HOST:23, sim:grbl (a simulated GRBL; "
                  "sim:grbl?speed=50 moves 50 times faster), m2nano://usb/1a86:5512 (a K40's M2 Nano board), "
                  "sim:m2nano (a simulated one), spool:DIR[?printer=NAME] (EPS for a print driver, sent to lp)")
      ->required();
  run->add_option("--sheet", options->sheet, "Only this sheet (1-based)")->check(CLI::PositiveNumber);
  run->add_flag("--frame", options->frame, "Trace each sheet's box with the laser off before cutting it");
  run->add_flag("--dry-run", options->dryRun, "Write what would be sent to --out instead of sending it");
  run->add_option("--out", options->out,
                  "With --dry-run: the file for the bytes (G-code for GRBL, .egv for the M2 Nano, EPS for the spool)");
  run->add_option("--machine", options->machine, "Machine profile (default: the first whose driver the URI names)");
  run->add_option("--material", options->material, "Material profile: power and speed overrides")
      ->capture_default_str();
  run->footer(
      "Cuts etch, then score, then inner cuts, then outer cuts, each with the machine profile's power, speed and\n"
      "passes. Ctrl-C stops the job and leaves the laser off (GRBL: feed hold, reset, M5; M2 Nano: \"I\", which\n"
      "drops the board's queue, then a home). Exit status 3 on a device fault.\n\n"
      "Examples:\n"
      "  rotafab make examples/cube.obj --structure band --machine grbl-diode-400 --out cube/\n"
      "  rotafab run cube/ --device sim:grbl\n"
      "  rotafab run cube/ --sheet 1 --device grbl:///dev/ttyUSB0 --frame\n"
      "  rotafab run cube/ --device grbl:///dev/ttyUSB0 --dry-run --out cube.gcode\n"
      "  rotafab make examples/cube.obj --structure band --machine k40-m2nano --out k40/\n"
      "  rotafab run k40/ --sheet 1 --device m2nano://usb/1a86:5512\n"
      "  rotafab run k40/ --sheet 1 --device m2nano://usb/1a86:5512 --dry-run --out sheet1.egv");
  run->callback([options, &status, argv] { status = runRun(*options, argv); });
}

}  // namespace rotafab::cli
