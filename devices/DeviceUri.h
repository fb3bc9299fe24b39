#pragma once
// SPEC's device URIs, and the device each names:
//   grbl:///dev/ttyUSB0?baud=115200   GRBL over serial (baud default 115200)
//   grbl+tcp://host:23                GRBL over telnet (ESP32 boards, ser2net)
//   sim:grbl[?speed=N]                a simulated GRBL on a pseudo-terminal, in this process
//                                     (its machine moving N times faster than real, default 1)
//   spool:DIR[?printer=NAME]          EPS files for a print-driver cutter, optionally sent to `lp`
//   m2nano://usb/1a86:5512, sim:m2nano   (issue 5: still to come)

#include <map>
#include <memory>
#include <string>

#include "devices/Device.h"

namespace rotafab::devices {

struct DeviceUri {
  std::string driver;     // "grbl", "m2nano", "spool"
  std::string transport;  // "serial", "tcp", "sim", "usb", "folder"
  std::string path;       // /dev/ttyUSB0, host, DIR
  std::string port;       // TCP port
  unsigned baud = 115200;
  double simulatedSpeed = 1;  // sim: simulated seconds per real second
  std::string printer;        // spool: the printer for lp, or none
};

// Throws std::invalid_argument naming what is wrong with the URI.
DeviceUri parseDeviceUri(const std::string& uri);

// The device, not yet connected (a simulator starts at once). Throws
// std::invalid_argument for a driver that is not built yet.
// `colours`: the machine profile's colour per operation (the spool draws in them).
std::unique_ptr<Device> openDevice(const DeviceUri& uri, const std::map<jobs::Operation, jobs::Rgb>& colours = {});

}  // namespace rotafab::devices
