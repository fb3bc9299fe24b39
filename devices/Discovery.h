#pragma once
// The cutters plugged in (issue 5, `rotafab devices`): serial ports from
// libserialport (name, description, USB vendor and product, serial number)
// and USB devices from libusb (the M2 Nano's CH341 in parallel mode has no
// serial port), each with the driver that fits it and the URI to give `run`.

#include <string>
#include <vector>

namespace rotafab::devices {

struct FoundDevice {
  std::string port;               // /dev/ttyUSB0, or usb:BUS:ADDRESS
  std::string description;        // "USB Serial", "CH341 parallel (M2 Nano)"
  int vendor = -1, product = -1;  // USB ids, -1 when not USB
  std::string serial;             // the USB serial number, when it has one
  std::string driver;             // "grbl", "m2nano", or "" when none fits
  std::string uri;                // for --device, when a driver fits
};

// What is plugged in now; never throws (a library that cannot enumerate gives nothing).
std::vector<FoundDevice> findDevices();

// The driver for a USB vendor:product: CH340 1a86:7523, FTDI 0403:6001, Arduino boards (2341:*, 2a03:*),
// CP210x 10c4:ea60 -> grbl; CH341 in parallel mode 1a86:5512 -> m2nano.
std::string driverForUsb(int vendor, int product);

}  // namespace rotafab::devices
