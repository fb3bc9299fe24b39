#pragma once
// The line protocol between a RemoteDevice and the DeviceHost in its helper
// process: one JSON object a line, each way.
//
//   to the host:   {"op": "connect" | "home" | "status" | "stop" | "disconnect"}
//                  (stop: Device::stopSafely(), replied {"ok": true, "confirmed": BOOL})
//                  {"op": "frame" | "run", "toolpath": TOOLPATH}
//                  {"op": "pause" | "resume" | "cancel"}       (while a run goes on; no reply)
//   to the device: {"ok": true, "identity": "...", "status": {...}} (the reply to a request)
//                  {"progress": PROGRESS}                      (while a run goes on)
//                  {"fault": {"kind": "timeout", "message": "...", "confirmed": true}}
//                  {"error": "..."}                            (anything else that went wrong)
//
// A toolpath goes whole, every double as the shortest decimal that reads
// back to it exactly, so the helper runs the very job planned here.

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string_view>

#include "devices/Device.h"

namespace rotafab::devices::remote {

nlohmann::json toJson(const jobs::Toolpath& toolpath);
jobs::Toolpath toolpathOf(const nlohmann::json& json);  // throws nlohmann::json::exception

nlohmann::json toJson(const Progress& progress);
Progress progressOf(const nlohmann::json& json);

nlohmann::json toJson(const DeviceFault& fault);
DeviceFault faultOf(const nlohmann::json& json);

std::optional<FaultKind> faultKindNamed(std::string_view name);

}  // namespace rotafab::devices::remote
