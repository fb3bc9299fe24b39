#pragma once
// A USB device on libusb-1.0: the M2 Nano's CH341 bridge, or
// anything else that talks in control and bulk transfers. Every transfer has
// a timeout. Errors become DeviceFaults: the device gone (unplugged) is
// Disconnected, a transfer that does not finish in time is Timeout, no
// permission to open it is Refused (with the fix), anything else Protocol.
// One thread uses a link.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "devices/Device.h"
#include "devices/transport/SerialLink.h"

struct libusb_context;
struct libusb_device_handle;

namespace rotafab::devices {

struct UsbMatch {
  uint16_t vendor = 0, product = 0;
  std::optional<int> bus, address;  // when several devices of the same kind are plugged in
};

class UsbLink {
 public:
  // Opens the first device that matches, detaches a kernel driver bound to
  // `interfaceNumber` and claims it. Throws DeviceFault (Disconnected when
  // there is no such device).
  static std::unique_ptr<UsbLink> open(const UsbMatch& match, int interfaceNumber);
  ~UsbLink();
  UsbLink(const UsbLink&) = delete;
  UsbLink& operator=(const UsbLink&) = delete;

  // A control transfer; returns the bytes transferred (for device-to-host requests, into `data`).
  size_t control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data, uint16_t length,
                 Millis timeout);
  void bulkWrite(uint8_t endpoint, const uint8_t* data, size_t length, Millis timeout);
  // Returns the bytes read; nothing when `timeout` passes first.
  std::optional<size_t> bulkRead(uint8_t endpoint, uint8_t* data, size_t length, Millis timeout);

  // "usb 001:004 (1a86:5512)"
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  UsbLink() = default;
  [[noreturn]] void fail(int error, const char* doing) const;

  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  int interface_ = 0;
  bool claimed_ = false;
  std::string name_;
};

}  // namespace rotafab::devices
