#include "devices/Discovery.h"

#include <fmt/format.h>
#include <libserialport.h>
#include <libusb.h>

namespace rotafab::devices {

std::string driverForUsb(int vendor, int product) {
  if (vendor == 0x1a86 && product == 0x5512) return "m2nano";
  if ((vendor == 0x1a86 && product == 0x7523) || (vendor == 0x0403 && product == 0x6001) ||
      (vendor == 0x10c4 && product == 0xea60) || vendor == 0x2341 || vendor == 0x2a03) {
    return "grbl";
  }
  return "";
}

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
        device.driver = driverForUsb(device.vendor, device.product);
      }
      if (device.driver == "grbl") device.uri = fmt::format("grbl://{}?baud=115200", device.port);
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
      if (driverForUsb(descriptor.idVendor, descriptor.idProduct) != "m2nano") continue;
      FoundDevice device;
      device.port = fmt::format("usb:{:03}:{:03}", libusb_get_bus_number(list[i]), libusb_get_device_address(list[i]));
      device.description = "CH341 in parallel mode (Lihuiyu M2 Nano, K40)";
      device.vendor = descriptor.idVendor, device.product = descriptor.idProduct;
      device.driver = "m2nano";
      device.uri = "m2nano://usb/1a86:5512";
      found.push_back(std::move(device));
    }
    if (count >= 0) libusb_free_device_list(list, 1);
    libusb_exit(usb);
  }
  return found;
}

}  // namespace rotafab::devices
