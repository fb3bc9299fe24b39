#pragma once
// The drivers as the rest of the program knows them, registered from their
// own folders (libsigrok's SR_REGISTER_DEV_DRIVER is the model): each says
// which device URIs it takes (docs/CONTRACT.md, "Devices"), which USB devices it drives,
// how to parse its URI into an address of its own kind and how to open the
// device; the device itself says what a dry run of it writes (Device::program).
// Discovery, URI parsing and the loop that runs a job ask the registry;
// nothing outside a driver's folder knows a driver by its name.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "devices/Device.h"

namespace rotafab::devices {

// A device URI parsed by its driver, into the driver's own fields.
class DeviceAddress {
 public:
  explicit DeviceAddress(std::string uri) : uri_(std::move(uri)) {}
  virtual ~DeviceAddress() = default;
  [[nodiscard]] const std::string& uri() const { return uri_; }

 private:
  std::string uri_;
};

// What a device is opened with besides its address.
struct DeviceSetup {
  std::map<jobs::Operation, jobs::Rgb> colours;  // the machine profile's colour per operation (the spool draws in them)
  // The machine profile's motion, for a controller that cannot be asked
  // for its own (a Ruida's are on its panel), and its bed, inches.
  jobs::MotionLimits motion;
  double bedWidth = 0, bedHeight = 0;
};

// A USB device a driver drives: vendor and product (no product: any of the vendor's).
struct UsbId {
  uint16_t vendor = 0;
  std::optional<uint16_t> product;
};

class DriverEntry {
 public:
  virtual ~DriverEntry() = default;
  // The driver as machine profiles name it: "grbl", "m2nano", "spool".
  [[nodiscard]] virtual std::string_view name() const = 0;
  // The start of its URIs, for messages: "grbl://", "sim:grbl".
  [[nodiscard]] virtual std::string_view scheme() const = 0;
  // Whether it drives a simulated device.
  [[nodiscard]] virtual bool simulated() const { return false; }
  // Whether the URI is one of this driver's (by its scheme).
  [[nodiscard]] virtual bool takes(std::string_view uri) const = 0;
  // For discovery: the USB devices it drives, and the URI for one found,
  // as a serial port or as a USB device (empty when it drives none so).
  [[nodiscard]] virtual std::vector<UsbId> usbIds() const { return {}; }
  [[nodiscard]] virtual std::string uriForSerialPort(const std::string& /*port*/) const { return {}; }
  [[nodiscard]] virtual std::string uriForUsbDevice(int /*bus*/, int /*address*/) const { return {}; }
  [[nodiscard]] virtual std::string usbDescription() const { return {}; }
  // For discovery: the devices it finds on the network, each as its URI
  // and what it is (a moment's wait; nothing when it finds none so).
  struct NetworkDevice {
    std::string uri, description;
  };
  [[nodiscard]] virtual std::vector<NetworkDevice> findOnNetwork() const { return {}; }
  // Throws std::invalid_argument "URI: what is wrong (e.g. AN EXAMPLE)".
  [[nodiscard]] virtual std::unique_ptr<DeviceAddress> parse(const std::string& uri) const = 0;
  // The device, not connected yet (a simulator starts at once).
  [[nodiscard]] virtual std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup& setup) const = 0;
  // Dry runs write the bytes the device would be sent (Device::program()).
  // Whether the device must be connected for one (a simulator is asked for
  // its settings; a real port is never opened), and what to say before a
  // dry run that opens nothing.
  [[nodiscard]] virtual bool connectsForDryRun(const DeviceAddress& /*address*/) const { return false; }
  [[nodiscard]] virtual std::string dryRunNote(const DeviceAddress& /*address*/) const { return {}; }
  // Whether the device can trace a sheet's box with the laser off
  // (Device::frame()); a print spool only writes files.
  [[nodiscard]] virtual bool frames() const { return true; }
};

// Every driver, in the order discovery lists what they find.
const std::vector<const DriverEntry*>& drivers();

// A URI and the driver that parsed it.
struct ParsedUri {
  const DriverEntry* driver = nullptr;
  std::unique_ptr<DeviceAddress> address;
};
// Throws std::invalid_argument naming what is wrong with the URI.
ParsedUri parseDeviceUri(const std::string& uri);

// The drivers of a USB device, the likeliest first (one chip may be in several controllers).
std::vector<const DriverEntry*> driversForUsb(int vendor, int product);

}  // namespace rotafab::devices
