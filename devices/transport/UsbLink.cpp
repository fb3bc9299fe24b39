#include "devices/transport/UsbLink.h"

#include <fmt/format.h>
#include <libusb.h>

namespace rotafab::devices {
namespace {

FaultKind faultOf(int error) {
  switch (error) {
    case LIBUSB_ERROR_NO_DEVICE:
    case LIBUSB_ERROR_NOT_FOUND:
      return FaultKind::Disconnected;
    case LIBUSB_ERROR_TIMEOUT:
      return FaultKind::Timeout;
    case LIBUSB_ERROR_ACCESS:
    case LIBUSB_ERROR_BUSY:
      return FaultKind::Refused;
    default:
      return FaultKind::Protocol;
  }
}

unsigned timeoutOf(Millis timeout) { return static_cast<unsigned>(std::max<long>(1, timeout.count())); }

}  // namespace

std::unique_ptr<UsbLink> UsbLink::open(const UsbMatch& match, int interfaceNumber) {
  std::unique_ptr<UsbLink> link(new UsbLink());
  link->name_ = fmt::format("usb {:04x}:{:04x}", match.vendor, match.product);
  if (const int error = libusb_init(&link->context_); error != 0) {
    link->context_ = nullptr;
    throw DeviceFault(FaultKind::Disconnected,
                      fmt::format("{}: libusb cannot start: {}", link->name_, libusb_error_name(error)));
  }
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(link->context_, &list);
  libusb_device* found = nullptr;
  for (ssize_t i = 0; i < count && !found; ++i) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
    if (descriptor.idVendor != match.vendor || descriptor.idProduct != match.product) continue;
    if (match.bus && libusb_get_bus_number(list[i]) != *match.bus) continue;
    if (match.address && libusb_get_device_address(list[i]) != *match.address) continue;
    found = list[i];
  }
  int error = LIBUSB_ERROR_NOT_FOUND;
  if (found) {
    link->name_ = fmt::format("usb {:03}:{:03} ({:04x}:{:04x})", libusb_get_bus_number(found),
                              libusb_get_device_address(found), match.vendor, match.product);
    error = libusb_open(found, &link->handle_);
  }
  if (count >= 0) libusb_free_device_list(list, 1);
  if (!found) {
    throw DeviceFault(
        FaultKind::Disconnected,
        fmt::format("{}: no such USB device is plugged in (`rotafab devices` lists what is)", link->name_));
  }
  if (error != 0) {
    link->handle_ = nullptr;
    if (error == LIBUSB_ERROR_ACCESS) {
      throw DeviceFault(FaultKind::Refused,
                        fmt::format("{}: no permission to open it: run as a user a udev rule lets in "
                                    "(SUBSYSTEM==\"usb\", ATTR{{idVendor}}==\"{:04x}\", ATTR{{idProduct}}==\"{:04x}\", "
                                    "MODE=\"0666\")",
                                    link->name_, match.vendor, match.product));
    }
    link->fail(error, "opening it");
  }
  // A kernel driver (usblp, ch341 in serial mode) may hold the interface.
  if (libusb_kernel_driver_active(link->handle_, interfaceNumber) == 1) {
    if (const int detach = libusb_detach_kernel_driver(link->handle_, interfaceNumber); detach != 0) {
      link->fail(detach, "detaching the kernel's driver");
    }
  }
  if (const int claim = libusb_claim_interface(link->handle_, interfaceNumber); claim != 0) {
    link->fail(claim, "claiming its interface (is another program driving it?)");
  }
  link->interface_ = interfaceNumber;
  link->claimed_ = true;
  return link;
}

UsbLink::~UsbLink() {
  if (handle_) {
    if (claimed_) libusb_release_interface(handle_, interface_);
    libusb_close(handle_);
  }
  if (context_) libusb_exit(context_);
}

void UsbLink::fail(int error, const char* doing) const {
  const FaultKind kind = faultOf(error);
  throw DeviceFault(kind, fmt::format("{}: {}: {}", name_, doing,
                                      kind == FaultKind::Disconnected ? "the device is gone (unplugged?)"
                                      : kind == FaultKind::Timeout    ? "it did not answer in time"
                                                                      : libusb_error_name(error)));
}

size_t UsbLink::control(uint8_t requestType, uint8_t request, uint16_t value, uint16_t index, uint8_t* data,
                        uint16_t length, Millis timeout) {
  const int done =
      libusb_control_transfer(handle_, requestType, request, value, index, data, length, timeoutOf(timeout));
  if (done < 0) fail(done, fmt::format("control request 0x{:02x}", request).c_str());
  return static_cast<size_t>(done);
}

void UsbLink::bulkWrite(uint8_t endpoint, const uint8_t* data, size_t length, Millis timeout) {
  int done = 0;
  const int error = libusb_bulk_transfer(handle_, endpoint, const_cast<uint8_t*>(data), static_cast<int>(length), &done,
                                         timeoutOf(timeout));
  if (error != 0) fail(error, "writing");
  if (static_cast<size_t>(done) != length) {
    throw DeviceFault(FaultKind::Timeout, fmt::format("{}: wrote {} of {} bytes", name_, done, length));
  }
}

std::optional<size_t> UsbLink::bulkRead(uint8_t endpoint, uint8_t* data, size_t length, Millis timeout) {
  int done = 0;
  const int error = libusb_bulk_transfer(handle_, endpoint, data, static_cast<int>(length), &done, timeoutOf(timeout));
  if (error == LIBUSB_ERROR_TIMEOUT && done == 0) return std::nullopt;
  if (error != 0 && error != LIBUSB_ERROR_TIMEOUT) fail(error, "reading");
  return static_cast<size_t>(done);
}

}  // namespace rotafab::devices
