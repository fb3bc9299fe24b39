#include "cli/RunCommand.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "cli/CommandContext.h"
#include "cli/CommandSupport.h"
#include "cli/RunProgress.h"
#include "devices/JobRun.h"
#include "toolpath/JobSheets.h"
#include "toolpath/ManifestFile.h"

namespace rotafab::cli {
namespace {

struct RunOptions {
  std::string target, device, out, machine, material, units;
  std::optional<int> sheet, fromStroke;
  bool frame = false, yes = false, dryRun = false, force = false;
};

// The device to cut on: the one given, else the connection of the machine
// profile the job is cut on (the one given, else the job's own).
std::string deviceFor(const RunOptions& options, const profiles::ProfileCatalogue& catalogue,
                      const jobs::JobProfileNames& madeFor) {
  if (!options.device.empty()) return options.device;
  const std::string machine = !options.machine.empty() ? options.machine : madeFor.machine.value_or("");
  if (machine.empty()) {
    throw UserError(
        fmt::format("{}: its manifest names no machine whose connection to use; give --device URI", options.target));
  }
  const profiles::MachineProfile profile = profiles::findMachine(catalogue, machine);
  if (profile.connection.empty()) {
    throw UserError(fmt::format("the machine profile {} ({}) names no connection; give --device URI", profile.name,
                                profile.source.string()));
  }
  return profile.connection;
}

// A job cut with other settings than it was made for (another machine or
// material, or the driver's machine where the job's is another's): said,
// then asked on a terminal, or refused without --force.
void confirmChanges(const RunOptions& options, const jobs::JobProfileNames& madeFor,
                    const jobs::CuttingProfiles& cutting, const core::Cancellation& cancel) {
  if (cutting.changes.empty()) return;
  const std::string made =
      fmt::format("{} was made for {} with {}", options.target, madeFor.machine.value_or(cutting.machine.name),
                  madeFor.material.value_or(cutting.material.name));
  const std::string changes = fmt::format("{}", fmt::join(cutting.changes, "; "));
  if (options.force) {
    fmt::print(stderr, "run: {}; cut with --force: {}\n", made, changes);
    return;
  }
  if (::isatty(STDIN_FILENO) == 0) {
    throw UserError(
        fmt::format("{}; cutting it on {} with {} changes {}; add --force to cut it so, or leave out "
                    "--machine and --material to cut it as it was made",
                    made, cutting.machine.name, cutting.material.name, changes));
  }
  fmt::print(stderr, "run: {}; cutting it on {} with {} changes {}.\nCut it with these settings? [y/N] ", made,
             cutting.machine.name, cutting.material.name, changes);
  std::fflush(stderr);
  const std::optional<std::string> answer = readLine(cancel);  // (Ctrl-C stops it at once)
  if (!answer || (*answer != "y" && *answer != "Y" && *answer != "yes")) {
    throw UserError("not cut: the settings were not confirmed");
  }
}

int cut(const RunOptions& options, devices::JobRun& job, CommandContext& command, std::string stock,
        std::map<int, std::string> kits, core::LengthUnit unit) {
  const auto& toolpaths = job.toolpaths();
  if (toolpaths.size() > 1 && !::isatty(STDIN_FILENO)) {
    throw UserError(
        fmt::format("{}: {} sheets, and no terminal to ask before each one that the next is loaded: "
                    "run them one at a time with --sheet N",
                    options.target, toolpaths.size()));
  }
  const auto started = std::chrono::steady_clock::now();
  devices::RunSummary done;
  try {
    done = job.run(terminalRunEvents(toolpaths.size(), command.cancellation(), std::move(stock), std::move(kits),
                                     {options.frame, options.yes}, unit),
                   command.cancellation());
  } catch (const devices::DeviceFault& fault) {
    // Where the job stopped, so that the operator knows what is cut and can
    // go on from that sheet; and what is true of the laser.
    const std::string where = fault.sheet == 0    ? std::string("before the first sheet")
                              : fault.nothingSent ? fmt::format("at sheet {}, before any of it was sent", fault.sheet)
                                                  : fmt::format("at sheet {}, with {} of its {} strokes cut",
                                                                fault.sheet, fault.strokesDone, fault.strokes);
    // To go on: the strokes cut are not cut again (after a frame, to check the sheet has not moved):
    // "leave sheet 1 and run it with --sheet 1 --from-stroke 102 --frame".
    const bool midSheet = fault.strokesDone > 0 && fault.strokesDone < fault.strokes;
    const std::string goOn =
        midSheet ? fmt::format("--sheet {} --from-stroke {} --frame", fault.sheet, fault.strokesDone + 1)
                 : fmt::format("--sheet {}", fault.sheet);
    const std::string laser = fault.nothingSent && fault.sheet > 1
                                  ? std::string("the sheets before it ended with the laser off")
                                  : devices::laserStateAfter(fault);
    if (fault.kind == devices::FaultKind::Cancelled) {
      // The operator's choice, not an error.
      fmt::print(stderr, "run: stopped {}; {}{}\n", where, laser,
                 fault.sheet > 0 ? fmt::format("; to go on, {} sheet {} and run it with {}",
                                               midSheet ? "leave" : "load", fault.sheet, goOn)
                                 : "");
      // (no signal: the operator did not say the next sheet was loaded)
      return command.signal() != 0 ? command.interruptedStatus() : kUserError;
    }
    fmt::print(stderr, "error: {} ({}; stopped {}; {}){}\n", fault.what(), devices::faultName(fault.kind), where, laser,
               fault.sheet > 0 ? fmt::format("; once it is fixed, go on with {}", goOn) : "");
    return kDeviceFault;
  }
  // The spool only writes the sheets (and hands them to the print queue): a print driver cuts them later.
  const bool spool = options.device.starts_with("spool:");
  const char* what = !spool                                                 ? "cut on"
                     : options.device.find("printer=") != std::string::npos ? "sent to the printer by"
                                                                            : "written as EPS by";
  fmt::print("{}: {} sheet{} {} {}: {} strokes, {} burnt, in {} (estimated {})\n", options.target, done.sheets,
             done.sheets == 1 ? "" : "s", what, options.device, done.strokes, unit(done.burnt, 1),
             minutes(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()),
             minutes(done.estimated));
  return kSuccess;
}

int runRun(const RunOptions& options) {
  return reportingErrors(options.target, [&]() -> int {
    // Ctrl-C and SIGTERM cancel the job from here on (before any device, a simulator's thread, starts).
    CommandContext command({}, 0, CommandContext::SecondSignal::Waits);
    try {
      devices::JobRunSetup setup;
      if (options.dryRun && options.out.empty()) throw UserError("--dry-run needs --out FILE: where the bytes go");
      if (options.frame && !options.yes && !options.dryRun && ::isatty(STDIN_FILENO) == 0) {
        throw UserError(
            "--frame stops after the frame for you to check the sheet, and there is no terminal to ask: add --yes "
            "to cut once framed");
      }
      const std::vector<jobs::JobSheet> sheets = jobs::readJobSheets(options.target, options.sheet);
      const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
      const jobs::JobProfileNames madeFor = jobs::jobProfileNames(options.target);
      const std::string device = deviceFor(options, catalogue, madeFor);
      try {
        setup.device = devices::parseDeviceUri(device);
      } catch (const std::invalid_argument& error) {
        throw UserError(fmt::format("--device {}", error.what()));
      }
      const std::string_view driverName = setup.device.driver->name();
      if (options.frame && !setup.device.driver->frames()) {
        throw UserError(
            fmt::format("--frame: {} writes files for a print driver and moves no head to frame a sheet "
                        "with; frame it from the cutter's own software",
                        device));
      }
      jobs::CuttingProfiles cutting =
          jobs::cuttingProfiles(catalogue, madeFor, options.machine, options.material, driverName);
      if (cutting.machine.driver != driverName) {
        throw UserError(fmt::format("--machine {} is driven by {}, not by --device {}'s {} driver",
                                    cutting.machine.name, cutting.machine.driver, device, driverName));
      }
      // --units, else the user's setting, else the job's, else the machine's bed's.
      const core::LengthUnit unit = unitShown(
          options.units, madeFor.shownIn.value_or(profiles::shownUnit("", std::nullopt, "", cutting.machine.bed.unit)));
      jobs::checkSheetsFitBed(sheets, cutting.machine, unit);
      confirmChanges(options, madeFor, cutting, command.cancellation());
      // (The job's sheets' own size: a bed larger than theirs holds them as they are.)
      std::string stock =
          jobs::stockOf(cutting.material, sheets.front().drawing.width, sheets.front().drawing.height, unit);
      RunOptions resolved = options;
      resolved.device = device;
      setup.machine = std::move(cutting.machine);
      setup.material = std::move(cutting.material);
      for (const jobs::JobSheet& sheet : sheets) setup.sheets.push_back(sheet.drawing);
      setup.dryRun = options.dryRun;
      setup.fromStroke = options.fromStroke ? static_cast<size_t>(*options.fromStroke - 1) : 0;
      setup.cancellation = &command.cancellation();
      setup.connected = [&](const std::string& identity) { fmt::print(stderr, "run: {}: {}\n", device, identity); };
      const auto& driver = *setup.device.driver;
      if (options.dryRun && !driver.connectsForDryRun(*setup.device.address)) {
        if (const std::string note = driver.dryRunNote(*setup.device.address); !note.empty()) {
          fmt::print(stderr, "run: {}\n", note);
        }
      }
      std::unique_ptr<devices::JobRun> job;
      try {
        job = std::make_unique<devices::JobRun>(std::move(setup));
      } catch (const std::invalid_argument& error) {
        throw UserError(error.what());
      }
      if (const size_t strokes = job->toolpaths().front().strokes.size();
          options.fromStroke && static_cast<size_t>(*options.fromStroke) > strokes) {
        throw UserError(
            fmt::format("--from-stroke {}: sheet {} has {} strokes", *options.fromStroke, *options.sheet, strokes));
      }
      if (!options.dryRun) {
        // Each sheet's kit, said as it is loaded and cut, where the folder's manifest gives them.
        std::map<int, std::string> kits;
        if (const auto manifest = std::filesystem::path(options.target) / "manifest.json";
            std::filesystem::is_directory(options.target) && std::filesystem::exists(manifest)) {
          if (const auto read = jobs::readManifestSheets(manifest)) kits = read->kits;
        }
        return cut(resolved, *job, command, std::move(stock), std::move(kits), unit);
      }
      if (command.cancellation().cancelled()) {
        fmt::print(stderr, "run: stopped; nothing was written\n");
        return command.interruptedStatus();
      }
      if (job->toolpaths().size() > 1) {
        // One file a sheet, cube.gcode -> cube-sheet-001.gcode, ...: one
        // file of several sheets would be cut back to back, onto one sheet.
        const std::filesystem::path out = options.out;
        if (out.stem().empty()) {
          throw UserError(
              fmt::format("--out {}: {} sheets are written as NAME-sheet-001{} and on: give a file "
                          "name, such as cube.gcode",
                          options.out, job->toolpaths().size(), out.extension().string()));
        }
        for (const std::string& written : job->writeDryRunOfEachSheet([&](int sheet) {
               return out.parent_path() /
                      fmt::format("{}-sheet-{:03}{}", out.stem().string(), sheet, out.extension().string());
             })) {
          fmt::print("{}\n", written);
        }
        return kSuccess;
      }
      fmt::print("{}: {}\n", options.out, job->writeDryRun(options.out));
      return kSuccess;
    } catch (const devices::DeviceFault& fault) {
      if (fault.kind == devices::FaultKind::Cancelled && command.signal() != 0) {
        fmt::print(stderr, "run: stopped before the first sheet; {}\n", devices::laserStateAfter(fault));
        return command.interruptedStatus();
      }
      fmt::print(stderr, "error: {} ({}; {})\n", fault.what(), devices::faultName(fault.kind),
                 devices::laserStateAfter(fault));
      return kDeviceFault;
    }
  });
}

}  // namespace

void addRunCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* run = app.add_subcommand("run", "Drive a cutter directly: cut the sheets of a `make` output");
  run->add_option("TARGET", options->target, "An output folder of `rotafab make`, or one sheet's .svg")->required();
  run->add_option(
      "--device", options->device,
      "Device URI (default: the connection of the job's machine profile): grbl:///dev/ttyUSB0?baud=115200, "
      "grbl+tcp://HOST:23, sim:grbl (a simulated GRBL; "
      "50 times faster than the machine by default; ?speed=1 for real time), m2nano://usb/1a86:5512 (a K40's M2 "
      "Nano board), "
      "sim:m2nano (a simulated one), ruida://IP[?magic=0x11] (a CO2 laser's Ruida controller on the network), "
      "ruida+serial:///dev/ttyUSB0 (on its USB port), sim:ruida (a simulated one), spool:DIR[?printer=NAME] (EPS "
      "for a print driver, sent to lp)");
  run->add_option("--sheet", options->sheet, "Only this sheet (1-based)")->check(CLI::PositiveNumber);
  run->add_flag("--frame", options->frame,
                "Trace each sheet's box with the laser off (or at the machine profile's frame_power), then ask \"cut "
                "sheet N now?\" (y cuts, f frames again)");
  run->add_flag("--yes", options->yes, "With --frame: cut once framed without asking");
  run->add_option("--from-stroke", options->fromStroke,
                  "With --sheet: go on from this stroke (1-based), as a stopped run says; the strokes before it "
                  "are not cut again")
      ->check(CLI::PositiveNumber);
  addUnitsOption(run, options->units);
  run->add_flag("--dry-run", options->dryRun, "Write what would be sent to --out instead of sending it");
  run->add_option("--out", options->out,
                  "With --dry-run: the file for the bytes (G-code for GRBL, .egv for the M2 Nano, EPS for the spool); "
                  "of several sheets, one file each beside it: --out cube.gcode writes cube-sheet-001.gcode, ...");
  run->add_option("--machine", options->machine,
                  "Machine profile (default: the job's, from its manifest; where --device's driver drives another, "
                  "the first that driver drives)");
  run->add_option("--material", options->material,
                  "Material profile: its power, speed and passes for the machine (default: the job's, from its "
                  "manifest, else posterboard)");
  run->add_flag("--force", options->force,
                "Cut with another machine or material than the job was made for without asking (it says what "
                "changes; without a terminal, run refuses such a cut unless --force)");
  run->footer(
      "Cuts etch, then score, then inner cuts, then outer cuts, each with the power, speed and passes of the\n"
      "machine and material the job was made for (its manifest names them); another --machine or --material\n"
      "says what changes and asks first (or needs --force). Ctrl-C stops the job and leaves the laser off (GRBL: feed "
      "hold, reset, M5; M2 Nano: \"I\", which\n"
      "drops the board's queue, then a home). Exit status 3 on a device fault.\n\n"
      "Examples:\n"
      "  rotafab make examples/cube.obj --structure band --machine grbl-diode-400 --out cube/\n"
      "  rotafab run cube/ --device sim:grbl\n"
      "  rotafab run cube/ --sheet 1   (on the machine profile's connection, grbl:///dev/ttyUSB0)\n"
      "  rotafab run cube/ --sheet 1 --device grbl:///dev/ttyUSB0 --frame\n"
      "  rotafab run cube/ --sheet 2 --from-stroke 144 --frame   (go on where a stopped run said)\n"
      "  rotafab run cube/ --device grbl:///dev/ttyUSB0 --dry-run --out cube.gcode\n"
      "  rotafab make examples/cube.obj --structure band --machine k40-m2nano --out k40/\n"
      "  rotafab run k40/ --sheet 1 --device m2nano://usb/1a86:5512\n"
      "  rotafab run k40/ --sheet 1 --device m2nano://usb/1a86:5512 --dry-run --out sheet1.egv");
  run->callback([options, &status] {
    // A safety check before anything opens a device: `--out` without
    // `--dry-run` would otherwise cut for real and write nothing.
    if (options->fromStroke && !options->sheet) {
      throw CLI::ValidationError("--from-stroke", "needs --sheet N: the sheet to go on with");
    }
    if (!options->out.empty() && !options->dryRun) {
      throw CLI::ValidationError("--out",
                                 "needs --dry-run: without it, run cuts on the device and writes no file; "
                                 "add --dry-run to write the bytes to " +
                                     options->out + " instead");
    }
    status = runRun(*options);
  });
}

}  // namespace rotafab::cli
