#include "cli/DevicesCommand.h"

#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/ExitStatus.h"
#include "cli/QueueCommands.h"
#include "devices/Discovery.h"

namespace rotafab::cli {
namespace {

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
      if (!d.otherwise.empty()) {
        entry["otherwise"] = nlohmann::ordered_json::array();
        for (const auto& [driver, uri] : d.otherwise) entry["otherwise"].push_back({{"driver", driver}, {"uri", uri}});
      }
      list.push_back(entry);
    }
    std::cout << list.dump() << '\n';
    return kSuccess;
  }
  for (const auto& d : found) {
    fmt::print("{}  {}", d.port, d.description.empty() ? "(no description)" : d.description);
    if (d.vendor >= 0) fmt::print("  usb {:04x}:{:04x}", d.vendor, d.product);
    if (!d.serial.empty()) fmt::print(" serial {}", d.serial);
    if (!d.uri.empty()) fmt::print("\n    {} driver: --device {}", d.driver, d.uri);
    for (const auto& [driver, uri] : d.otherwise)
      fmt::print("\n    or, if it is one, {} driver: --device {}", driver, uri);
    fmt::print("\n");
  }
  if (std::none_of(found.begin(), found.end(), [](const auto& d) { return !d.uri.empty(); })) {
    fmt::print(
        "{} (a GRBL board shows as /dev/ttyUSB* or /dev/ttyACM*: check the cable, and that you may open "
        "it, the dialout group){}.\n"
        "Without a cutter, the simulator takes a job as a GRBL board would: "
        "rotafab run FOLDER --device sim:grbl\n",
        found.empty() ? "no serial port or cutter found" : "no cutter recognised among these",
        found.empty() ? "" : "; a port above may still be one: --device grbl://PORT");
  }
  return kSuccess;
}

}  // namespace

void addDevicesCommand(CLI::App& app, int& status) {
  auto json = std::make_shared<bool>(false);
  auto daemon = std::make_shared<bool>(false);
  auto server = std::make_shared<std::string>();
  auto token = std::make_shared<std::string>();
  CLI::App* devicesCommand =
      app.add_subcommand("devices", "List the serial ports and cutters plugged in, and the driver for each");
  devicesCommand->add_flag("--json", *json,
                           "Print one JSON array: port, description, usb {vendor, product, serial}, driver, uri");
  devicesCommand->add_flag("--daemon", *daemon, "The daemon's devices instead: each with its state and job");
  devicesCommand->add_option("--server", *server, "With --daemon: unix:PATH or http://HOST:PORT (default: the socket)");
  devicesCommand->add_option("--token", *token, "With --daemon: the bearer token a TCP listener asks for");
  devicesCommand->footer(
      "Examples:\n"
      "  rotafab devices\n"
      "  rotafab devices --daemon");
  devicesCommand->callback([json, daemon, server, token, &status] {
    status = *daemon || !server->empty() ? runDaemonDevices(*json, *server, *token) : runDevices(*json);
  });
}

}  // namespace rotafab::cli
