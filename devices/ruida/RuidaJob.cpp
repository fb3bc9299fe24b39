#include "devices/ruida/RuidaJob.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace rotafab::devices::ruida {
namespace {

// The reach of a relative move's 14-bit operand, micrometres.
constexpr long kRelativeReach = 8191;

struct Micrometres {
  long x = 0, y = 0;
};

// A sheet point in the controller's frame (top-left origin, y down).
Micrometres machinePoint(const jobs::Point2& p, double height) {
  return {std::lround(p.x() * kMicrometresPerInch), std::lround((height - p.y()) * kMicrometresPerInch)};
}

void appendPoint(Bytes& out, Micrometres p) {
  appendU35(out, p.x);
  appendU35(out, p.y);
}

// The layers: one for each power and speed, in the order they are first burnt.
struct Layer {
  double power = 0, minPower = 0, speed = 0;  // 0..1, in/s
};

// The power where the head slows: the stroke's, never above its power.
double minPowerOf(const jobs::ToolpathStroke& stroke) {
  return stroke.minPower >= 0 ? std::min(stroke.minPower, stroke.power) : stroke.power;
}

size_t layerOf(std::vector<Layer>& layers, const jobs::ToolpathStroke& stroke) {
  for (size_t l = 0; l < layers.size(); ++l) {
    if (layers[l].power == stroke.power && layers[l].minPower == minPowerOf(stroke) && layers[l].speed == stroke.speed)
      return l;
  }
  layers.push_back({stroke.power, minPowerOf(stroke), stroke.speed});
  return layers.size() - 1;
}

long speedOf(double inchesPerSecond) { return std::lround(inchesPerSecond * kMicrometresPerInch); }

// A move (laser off) or a cut (lit) from `at` to `to`: relative where the
// 14-bit operand reaches, else absolute.
void appendStep(Bytes& out, Micrometres& at, Micrometres to, bool lit) {
  const long dx = to.x - at.x, dy = to.y - at.y;
  if (std::labs(dx) <= kRelativeReach && std::labs(dy) <= kRelativeReach) {
    if (dy == 0) {
      out.push_back(lit ? 0xAA : 0x8A);
      appendS14(out, static_cast<int>(dx));
    } else if (dx == 0) {
      out.push_back(lit ? 0xAB : 0x8B);
      appendS14(out, static_cast<int>(dy));
    } else {
      out.push_back(lit ? 0xA9 : 0x89);
      appendS14(out, static_cast<int>(dx));
      appendS14(out, static_cast<int>(dy));
    }
  } else {
    out.push_back(lit ? 0xA8 : 0x88);
    appendPoint(out, to);
  }
  at = to;
}

struct Bounds {
  Micrometres low, high;
};

Bounds boundsOf(const jobs::Toolpath& toolpath) {
  Micrometres low{std::numeric_limits<long>::max(), std::numeric_limits<long>::max()};
  Micrometres high{0, 0};
  for (const jobs::ToolpathStroke& stroke : toolpath.strokes) {
    for (const jobs::Point2& p : stroke.points) {
      const Micrometres m = machinePoint(p, toolpath.height);
      low = {std::min(low.x, m.x), std::min(low.y, m.y)};
      high = {std::max(high.x, m.x), std::max(high.y, m.y)};
    }
  }
  if (low.x > high.x) low = high = {0, 0};
  return {low, high};
}

void appendCommand(Bytes& out, std::initializer_list<uint8_t> bytes) { out.insert(out.end(), bytes); }

// The header: absolute coordinates from the machine's origin, the job's
// bounds, and each layer's speed, power and bounds.
void appendHeader(Bytes& out, const Bounds& bounds, const std::vector<Layer>& layers) {
  const auto command = [&out](std::initializer_list<uint8_t> bytes) { appendCommand(out, bytes); };
  const auto [low, high] = bounds;
  command({0xD8, 0x10});
  command({0xF0});
  command({0xF1, 0x02, 0x00});
  command({0xD8, 0x00});
  command({0xE7, 0x06});
  appendPoint(out, {0, 0});
  for (uint8_t bound : {0x03, 0x07, 0x50, 0x51}) {
    command({0xE7, bound});
    appendPoint(out, bound == 0x03 || bound == 0x50 ? low : high);
  }
  command({0xE7, 0x04, 0x00, 0x01, 0x00, 0x01});
  appendPoint(out, {0, 0});
  command({0xE7, 0x05, 0x00});
  for (size_t l = 0; l < layers.size(); ++l) {
    const auto layer = static_cast<uint8_t>(l);
    command({0xC9, 0x04, layer});
    appendU35(out, speedOf(layers[l].speed));
    for (uint8_t which : {0x31, 0x32}) {  // the laser's minimum and maximum power
      command({0xC6, which, layer});
      appendPower(out, 100 * (which == 0x31 ? layers[l].minPower : layers[l].power));
    }
    command({0xCA, 0x41, layer, 0x00});  // vector
    for (uint8_t bound : {0x52, 0x53, 0x61, 0x62}) {
      command({0xE7, bound, layer});
      appendPoint(out, bound == 0x52 || bound == 0x61 ? low : high);
    }
  }
  command({0xCA, 0x22, static_cast<uint8_t>(std::max<size_t>(layers.size(), 1) - 1)});
}

// The trailer: the end of the layers, the sum of every byte of the file but
// the sum's own command, the end of file.
void appendTrailer(Bytes& out) {
  appendCommand(out, {0xEB});
  appendCommand(out, {0xE7, 0x00});
  long sum = 0xD7;
  for (uint8_t b : out) sum += b;
  appendCommand(out, {0xE5, 0x05});
  appendU35(out, sum);
  appendCommand(out, {0xD7});
}

}  // namespace

Bytes frameStream(const jobs::Toolpath& toolpath) {
  const Bounds bounds = boundsOf(toolpath);
  Bytes out;
  appendHeader(out, bounds, {});
  // Moves only (88: absolute, laser off): nothing in the stream lights the laser.
  const Micrometres corners[] = {
      bounds.low, {bounds.high.x, bounds.low.y}, bounds.high, {bounds.low.x, bounds.high.y}, bounds.low};
  for (const Micrometres& corner : corners) {
    out.push_back(0x88);
    appendPoint(out, corner);
  }
  appendTrailer(out);
  return out;
}

Bytes jobStream(const jobs::Toolpath& toolpath, const RuidaJobOptions& options) {
  std::vector<Layer> layers;
  std::vector<size_t> strokeLayer;
  for (const jobs::ToolpathStroke& stroke : toolpath.strokes) strokeLayer.push_back(layerOf(layers, stroke));
  // A layer's number is one 7-bit operand byte.
  if (layers.size() > 0x7F) {
    throw std::invalid_argument(
        fmt::format("{} settings of power and speed on one sheet: a Ruida job holds 127 at most", layers.size()));
  }
  Bytes out;
  const auto command = [&out](std::initializer_list<uint8_t> bytes) { appendCommand(out, bytes); };
  appendHeader(out, boundsOf(toolpath), layers);
  // Body: each run of strokes of one layer behind that layer's settings.
  Micrometres at;
  bool placed = false;
  size_t current = layers.size();
  for (size_t s = 0; s < toolpath.strokes.size(); ++s) {
    const jobs::ToolpathStroke& stroke = toolpath.strokes[s];
    if (stroke.points.size() < 2) continue;
    if (strokeLayer[s] != current) {
      current = strokeLayer[s];
      const Layer& layer = layers[current];
      command({0xCA, 0x01, 0x00});
      command({0xCA, 0x02, static_cast<uint8_t>(current)});
      command({0xCA, 0x01, 0x10});
      command({0xCA, 0x01, static_cast<uint8_t>(options.airAssist ? 0x13 : 0x12)});
      command({0xC9, 0x02});
      appendU35(out, speedOf(layer.speed));
      for (uint8_t which : {0x01, 0x02}) {
        command({0xC6, which});
        appendPower(out, 100 * (which == 0x01 ? layer.minPower : layer.power));
      }
      command({0xCA, 0x03, 0x01});
    }
    const Micrometres start = machinePoint(stroke.points.front(), toolpath.height);
    if (!placed) {
      // The first move absolute, as the controllers want it.
      command({0x88});
      appendPoint(out, start);
      at = start, placed = true;
    } else {
      appendStep(out, at, start, false);
    }
    for (size_t i = 1; i < stroke.points.size(); ++i) {
      appendStep(out, at, machinePoint(stroke.points[i], toolpath.height), true);
    }
  }
  appendTrailer(out);
  return out;
}

std::optional<JobStep> JobReader::read(const Bytes& c) {
  if (c.empty()) return std::nullopt;
  const auto need = [&](size_t size) {
    if (c.size() < size) {
      throw std::invalid_argument(fmt::format("command {:02X}: {} bytes, want {}", c[0], c.size(), size));
    }
  };
  const uint8_t op = c[0];
  if (op == 0xE5 && c.size() >= 2 && c[1] == 0x05) {
    need(7);
    sumHolds_ = readU35(c.data() + 2) == sum_ + 0xD7;
    return std::nullopt;
  }
  for (uint8_t b : c) sum_ += b;
  const auto step = [&](long x, long y) {
    const bool lit = op >= 0xA8;
    JobStep s{x_, y_, x, y, lit, lit ? power_ : 0, speed_};
    x_ = x, y_ = y;
    return s;
  };
  if (op == 0x88 || op == 0xA8) {
    need(11);
    return step(static_cast<long>(readU35(c.data() + 1)), static_cast<long>(readU35(c.data() + 6)));
  }
  if (op == 0x89 || op == 0xA9) {
    need(5);
    return step(x_ + readS14(c.data() + 1), y_ + readS14(c.data() + 3));
  }
  if (op == 0x8A || op == 0xAA) {
    need(3);
    return step(x_ + readS14(c.data() + 1), y_);
  }
  if (op == 0x8B || op == 0xAB) {
    need(3);
    return step(x_, y_ + readS14(c.data() + 1));
  }
  if (op == 0xC9 && c.size() >= 2 && c[1] == 0x04) {
    need(8);
    layers_[c[2]].second = static_cast<double>(readU35(c.data() + 3));
  } else if (op == 0xC6 && c.size() >= 2 && c[1] == 0x32) {
    need(5);
    layers_[c[2]].first = readPower(c.data() + 3) / 100;
  } else if (op == 0xCA && c.size() >= 2 && c[1] == 0x02) {
    need(3);
    std::tie(power_, speed_) = layers_[c[2]];
  } else if (op == 0xC9 && c.size() >= 2 && c[1] == 0x02) {
    need(7);
    speed_ = static_cast<double>(readU35(c.data() + 2));
  } else if (op == 0xC6 && c.size() >= 2 && c[1] == 0x02) {
    need(4);
    power_ = readPower(c.data() + 2) / 100;
  } else if (op == 0xD7) {
    ended_ = true;
  }
  return std::nullopt;
}

DecodedJob decodeJob(const Bytes& stream, double height) {
  DecodedJob job;
  JobReader reader;
  bool lit = false;
  const auto sheetPoint = [height](long x, long y) {
    return jobs::Point2(static_cast<double>(x) / kMicrometresPerInch,
                        height - static_cast<double>(y) / kMicrometresPerInch);
  };
  for (const Bytes& c : splitCommands(stream)) {
    const auto step = reader.read(c);
    if (step && step->lit) {
      if (!lit || job.strokes.empty()) {
        job.strokes.push_back({step->power, step->speed / kMicrometresPerInch, {sheetPoint(step->fromX, step->fromY)}});
      }
      job.strokes.back().points.push_back(sheetPoint(step->toX, step->toY));
    }
    lit = step && step->lit;
  }
  job.ended = reader.ended();
  job.sumHolds = reader.sumHolds();
  return job;
}

}  // namespace rotafab::devices::ruida
