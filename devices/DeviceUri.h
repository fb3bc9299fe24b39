#pragma once
// SPEC's device URIs, and the device each names:
//   grbl:///dev/ttyUSB0?baud=115200   GRBL over serial (baud default 115200)
//   grbl+tcp://host:23                GRBL over telnet (ESP32 boards, ser2net)
//   sim:grbl[?speed=N]                a simulated GRBL on a pseudo-terminal, in this process
//                                     (its machine moving N times faster than real, default 1)
//   spool:DIR[?printer=NAME]          EPS files for a print-driver cutter, optionally sent to `lp`
//   m2nano://usb/1a86:5512[?bus=B&address=A]   a Lihuiyu M2 Nano (K40) on USB (the first one, or that one)
//   sim:m2nano[?speed=N]              a simulated M2 Nano plugged in through umockdev (the program
//                                     must run under umockdev's preload: sim::runUnderUmockdev)

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "devices/Device.h"

namespace rotafab::devices {

struct DeviceUri {
  std::string driver;     // "grbl", "m2nano", "spool"
  std::string transport;  // "serial", "tcp", "sim", "usb", "folder"
  std::string path;       // /dev/ttyUSB0, host, DIR
  std::string port;       // TCP port
  unsigned baud = 115200;
  double simulatedSpeed = 1;                         // sim: simulated seconds per real second
  std::string printer;                               // spool: the printer for lp, or none
  uint16_t usbVendor = 0x1a86, usbProduct = 0x5512;  // m2nano
  std::optional<int> usbBus, usbAddress;
};

// Throws std::invalid_argument naming what is wrong with the URI.
DeviceUri parseDeviceUri(const std::string& uri);

// The device, not yet connected (a simulator starts at once).
// `colours`: the machine profile's colour per operation (the spool draws in them).
std::unique_ptr<Device> openDevice(const DeviceUri& uri, const std::map<jobs::Operation, jobs::Rgb>& colours = {});

}  // namespace rotafab::devices
