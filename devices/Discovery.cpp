#include "devices/Discovery.h"

#include "devices/DriverEntry.h"

#include <fmt/format.h>

#include <libserialport.h>
#include <libusb.h>
#include <algorithm>

namespace rotafab::devices {

std::vector<FoundDevice> findDevices() {
  std::vector<FoundDevice> found;
  sp_port** ports = nullptr;
  if (sp_list_ports(&ports) == SP_OK) {
    for (sp_port** port = ports; *port; ++port) {
      FoundDevice device;
      device.port = sp_get_port_name(*port);
      if (const char* description = sp_get_port_description(*port)) device.description = description;
      if (sp_get_port_transport(*port) == SP_TRANSPORT_USB) {
        sp_get_port_usb_vid_pid(*port, &device.vendor, &device.product);
        if (const char* serial = sp_get_port_usb_serial(*port)) device.serial = serial;
        for (const DriverEntry* driver : driversForUsb(device.vendor, device.product)) {
          const std::string uri = driver->uriForSerialPort(device.port);
          if (uri.empty()) continue;
          if (device.uri.empty()) {
            device.uri = uri, device.driver = driver->name();
          } else {
            device.otherwise.emplace_back(driver->name(), uri);
          }
        }
      }
      found.push_back(std::move(device));
    }
    sp_free_port_list(ports);
  }
  libusb_context* usb = nullptr;
  if (libusb_init(&usb) == 0) {
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(usb, &list);
    for (ssize_t i = 0; i < count; ++i) {
      libusb_device_descriptor descriptor{};
      if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
      // Devices driven over USB itself (a serial adapter's port is listed above).
      const auto fitting = driversForUsb(descriptor.idVendor, descriptor.idProduct);
      const auto usbDriver = std::find_if(fitting.begin(), fitting.end(), [&](const DriverEntry* d) {
        return !d->uriForUsbDevice(libusb_get_bus_number(list[i]), libusb_get_device_address(list[i])).empty();
      });
      const DriverEntry* driver = usbDriver == fitting.end() ? nullptr : *usbDriver;
      const int bus = libusb_get_bus_number(list[i]), address = libusb_get_device_address(list[i]);
      if (!driver || driver->uriForUsbDevice(bus, address).empty()) continue;
      FoundDevice device;
      device.port = fmt::format("usb:{:03}:{:03}", bus, address);
      device.description = driver->usbDescription();
      device.vendor = descriptor.idVendor, device.product = descriptor.idProduct;
      device.driver = driver->name();
      device.uri = driver->uriForUsbDevice(bus, address);
      found.push_back(std::move(device));
    }
    if (count >= 0) libusb_free_device_list(list, 1);
    libusb_exit(usb);
  }
  for (const DriverEntry* driver : drivers()) {
    for (const auto& [uri, description] : driver->findOnNetwork()) {
      FoundDevice device;
      device.port = "network";
      device.description = description;
      device.driver = driver->name();
      device.uri = uri;
      found.push_back(std::move(device));
    }
  }
  return found;
}

}  // namespace rotafab::devices
