#pragma once
// The cutters plugged in (`rotafab devices`): serial ports from
// libserialport (name, description, USB vendor and product, serial number)
// and USB devices from libusb (the M2 Nano's CH341 in parallel mode has no
// serial port), each with the driver that fits it (as the registry of
// DriverEntry.h says) and the URI to give `run`.

#include <string>
#include <utility>
#include <vector>

namespace rotafab::devices {

struct FoundDevice {
  std::string port;               // /dev/ttyUSB0, or usb:BUS:ADDRESS
  std::string description;        // "USB Serial", "CH341 parallel (M2 Nano)"
  int vendor = -1, product = -1;  // USB ids, -1 when not USB
  std::string serial;             // the USB serial number, when it has one
  std::string driver;             // "grbl", "m2nano", or "" when none fits
  std::string uri;                // for --device, when a driver fits
  // Other drivers that may fit ("ruida+serial:///dev/ttyUSB0": a Ruida's USB
  // port is the same FTDI chip as many GRBL boards'), each driver and URI.
  std::vector<std::pair<std::string, std::string>> otherwise;
};

// What is plugged in now, and the controllers that answer on the local
// network; never throws (a library that cannot enumerate gives nothing).
std::vector<FoundDevice> findDevices();

}  // namespace rotafab::devices
