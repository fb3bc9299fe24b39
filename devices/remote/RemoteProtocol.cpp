#include "devices/remote/RemoteProtocol.h"

namespace rotafab::devices::remote {

nlohmann::json toJson(const jobs::Toolpath& toolpath) {
  nlohmann::json strokes = nlohmann::json::array();
  for (const jobs::ToolpathStroke& stroke : toolpath.strokes) {
    nlohmann::json points = nlohmann::json::array();
    for (const jobs::Point2& p : stroke.points) points.push_back({p.x(), p.y()});
    strokes.push_back({{"operation", profiles::operationName(stroke.operation)},
                       {"inner", stroke.inner},
                       {"power", stroke.power},
                       {"speed", stroke.speed},
                       {"pass", stroke.pass},
                       {"points", std::move(points)}});
  }
  return {{"sheet", toolpath.sheet},       {"width", toolpath.width},           {"height", toolpath.height},
          {"strokes", std::move(strokes)}, {"burn", toolpath.burnLength},       {"travel", toolpath.travelLength},
          {"seconds", toolpath.seconds},   {"frame_power", toolpath.framePower}};
}

jobs::Toolpath toolpathOf(const nlohmann::json& json) {
  jobs::Toolpath toolpath;
  toolpath.sheet = json.at("sheet").get<int>();
  toolpath.width = json.at("width").get<double>();
  toolpath.height = json.at("height").get<double>();
  for (const auto& s : json.at("strokes")) {
    jobs::ToolpathStroke stroke;
    const auto operation = profiles::operationNamed(s.at("operation").get<std::string>());
    if (!operation) throw nlohmann::json::other_error::create(501, "unknown operation", &s);
    stroke.operation = *operation;
    stroke.inner = s.at("inner").get<bool>();
    stroke.power = s.at("power").get<double>();
    stroke.speed = s.at("speed").get<double>();
    stroke.pass = s.at("pass").get<int>();
    for (const auto& p : s.at("points")) stroke.points.emplace_back(p.at(0).get<double>(), p.at(1).get<double>());
    toolpath.strokes.push_back(std::move(stroke));
  }
  toolpath.burnLength = json.at("burn").get<double>();
  toolpath.travelLength = json.at("travel").get<double>();
  toolpath.seconds = json.at("seconds").get<double>();
  toolpath.framePower = json.value("frame_power", 0.0);  // (a helper of before: dark frames)
  return toolpath;
}

nlohmann::json toJson(const Progress& p) {
  return {{"sheet", p.sheet},
          {"stroke", p.stroke},
          {"cut", p.strokesCut},
          {"strokes", p.strokes},
          {"acknowledged", p.bytesAcknowledged},
          {"total", p.bytesTotal},
          {"left", p.secondsLeft}};
}

Progress progressOf(const nlohmann::json& json) {
  Progress p;
  p.sheet = json.at("sheet").get<int>();
  p.stroke = json.at("stroke").get<size_t>();
  p.strokes = json.at("strokes").get<size_t>();
  p.strokesCut = json.at("cut").get<size_t>();
  p.bytesAcknowledged = json.at("acknowledged").get<size_t>();
  p.bytesTotal = json.at("total").get<size_t>();
  p.secondsLeft = json.at("left").get<double>();
  return p;
}

nlohmann::json toJson(const DeviceFault& fault) {
  return {{"kind", faultName(fault.kind)},
          {"message", fault.what()},
          {"confirmed", fault.laserOffConfirmed},
          {"nothing_sent", fault.nothingSent}};
}

std::optional<FaultKind> faultKindNamed(std::string_view name) {
  for (FaultKind kind : {FaultKind::Timeout, FaultKind::Disconnected, FaultKind::Alarm, FaultKind::Error,
                         FaultKind::Refused, FaultKind::Protocol, FaultKind::Cancelled, FaultKind::Stalled}) {
    if (faultName(kind) == name) return kind;
  }
  return std::nullopt;
}

DeviceFault faultOf(const nlohmann::json& json) {
  DeviceFault fault(faultKindNamed(json.at("kind").get<std::string>()).value_or(FaultKind::Protocol),
                    json.at("message").get<std::string>());
  fault.laserOffConfirmed = json.at("confirmed").get<bool>();
  fault.nothingSent = json.value("nothing_sent", false);  // (absent from an older end: not known, so false)
  return fault;
}

}  // namespace rotafab::devices::remote
