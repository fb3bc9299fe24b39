#include "devices/sim/RuidaSimulator.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <stdexcept>
#include <system_error>

#include "devices/ruida/RuidaChannel.h"

namespace rotafab::devices::sim {

using ruida::Bytes;

RuidaSimulator::RuidaSimulator(RuidaSimulatorOptions options) : options_(std::move(options)), swizzle_(options_.magic) {
  socket_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (socket_ < 0) throw std::system_error(errno, std::generic_category(), "sim:ruida: a UDP socket");
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  if (::bind(socket_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::getsockname(socket_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    const int error = errno;
    ::close(socket_);
    throw std::system_error(error, std::generic_category(), "sim:ruida: binding a loopback UDP port");
  }
  port_ = ntohs(address.sin_port);
  thread_ = std::thread([this] { serve(); });
}

RuidaSimulator::~RuidaSimulator() {
  quit_ = true;
  thread_.join();
  ::close(socket_);
  setLaser(false);
}

bool RuidaSimulator::jobRuns() const {
  std::lock_guard lock(mutex_);
  return jobStarted_;
}

std::vector<RuidaCut> RuidaSimulator::cuts() const {
  std::lock_guard lock(mutex_);
  return cuts_;
}

std::vector<std::string> RuidaSimulator::errors() const {
  std::lock_guard lock(mutex_);
  return errors_;
}

void RuidaSimulator::serve() {
  auto last = std::chrono::steady_clock::now();
  std::vector<uint8_t> buffer(65536);
  while (!quit_) {
    pollfd ready{socket_, POLLIN, 0};
    if (::poll(&ready, 1, 5) > 0 && (ready.revents & POLLIN)) {
      sockaddr_in from{};
      socklen_t fromLength = sizeof from;
      const ssize_t got =
          ::recvfrom(socket_, buffer.data(), buffer.size(), 0, reinterpret_cast<sockaddr*>(&from), &fromLength);
      if (got > 0) receive(Bytes(buffer.begin(), buffer.begin() + got), &from, fromLength);
    }
    const auto now = std::chrono::steady_clock::now();
    advance(std::chrono::duration<double>(now - last).count() * options_.timeScale);
    last = now;
  }
}

void RuidaSimulator::receive(const Bytes& datagram, const void* from, unsigned fromLength) {
  const size_t number = ++packets_;
  if (silent_) return;
  Bytes packet = datagram;
  if (options_.fault != RuidaFault::None && !faultDone_ && number >= options_.after) {
    faultDone_ = true;
    if (options_.fault == RuidaFault::Drop) return;
    if (options_.fault == RuidaFault::Corrupt && packet.size() > 2) packet.back() ^= 0x10;
    if (options_.fault == RuidaFault::Silence) {
      // Switched off: the job ends where it is, the laser with it, and nothing answers again.
      std::lock_guard lock(mutex_);
      silent_ = true;
      queue_.clear(), next_ = 0, into_ = 0;
      setLaser(false);
      return;
    }
  }
  const auto answer = [&](const Bytes& bytes) {
    const Bytes wire = swizzle_(bytes);
    ::sendto(socket_, wire.data(), wire.size(), 0, static_cast<const sockaddr*>(from), fromLength);
  };
  const Bytes payload = ruida::checkedPayload(packet);
  if (payload.empty()) {
    ++naks_;
    answer({ruida::kNak});
    return;
  }
  answer({ruida::kAck});
  std::lock_guard lock(mutex_);
  const Bytes plain = swizzle_.undo(payload);
  pending_.insert(pending_.end(), plain.begin(), plain.end());
  std::vector<Bytes> commands = ruida::splitCommands(pending_);
  pending_.clear();
  // The last command may go on in the next packet, unless it is one of
  // those that must act at once and is whole.
  if (!commands.empty()) {
    const Bytes& last = commands.back();
    const bool whole =
        (last[0] == 0xDA && last.size() >= 4) || (last[0] == 0xD8 && last.size() >= 2) || (last[0] == 0xD7);
    if (!whole) {
      pending_ = std::move(commands.back());
      commands.pop_back();
    }
  }
  for (const Bytes& c : commands) command(c, from, fromLength);
}

void RuidaSimulator::command(const Bytes& c, const void* from, unsigned fromLength) {
  const uint8_t op = c[0];
  if (op < 0x80) {
    errors_.push_back(fmt::format("{} bytes that are no command, starting {:02X}", c.size(), op));
    return;
  }
  if (op == 0xDA && c.size() >= 4 && c[1] == 0x00) {
    Bytes reply = {0xDA, 0x01, c[2], c[3]};
    ruida::appendU35(reply, memory(static_cast<uint16_t>(c[2] << 8 | c[3])));
    const Bytes wire = swizzle_(reply);
    ::sendto(socket_, wire.data(), wire.size(), 0, static_cast<const sockaddr*>(from), fromLength);
    return;
  }
  if (op == 0xD8 && c.size() >= 2) {
    switch (c[1]) {
      case 0x01:  // stop: the job ends now, the laser with it
        ++stops_;
        queue_.clear(), next_ = 0, into_ = 0;
        setLaser(false);
        jobStarted_ = jobEnded_ = paused_ = false;
        reader_ = {};
        pending_.clear();
        return;
      case 0x02:
        ++pauses_;
        paused_ = true;
        setLaser(false);
        return;
      case 0x03:
        paused_ = false;
        return;
      case 0x2A:  // home
        queue_.push_back({x_, y_, 0, 0, false, 0, options_.travelSpeed * 1000});
        return;
      default:
        break;  // the rest is the job's
    }
  }
  jobStarted_ = true;
  try {
    if (const auto step = reader_.read(c)) {
      const double speed = step->lit ? step->speed : options_.travelSpeed * 1000;
      if (!(speed > 0)) errors_.push_back(fmt::format("a cut at speed 0 (command {:02X})", op));
      queue_.push_back({static_cast<double>(step->fromX), static_cast<double>(step->fromY),
                        static_cast<double>(step->toX), static_cast<double>(step->toY), step->lit, step->power,
                        speed > 0 ? speed : options_.travelSpeed * 1000});
    }
  } catch (const std::invalid_argument& error) {
    errors_.push_back(error.what());
  }
  if (reader_.ended()) {
    if (!reader_.sumHolds()) errors_.push_back("the job's file sum (E5 05) does not match its bytes");
    jobEnded_ = true;
    reader_ = {};
  }
}

void RuidaSimulator::advance(double seconds) {
  std::lock_guard lock(mutex_);
  while (seconds > 0 && next_ < queue_.size() && !paused_ && !silent_) {
    const Segment& s = queue_[next_];
    setLaser(s.lit);
    const double length = std::hypot(s.x1 - s.x0, s.y1 - s.y0);
    const double left = length / s.speed - into_;
    if (seconds < left) {
      into_ += seconds;
      const double t = length > 0 ? into_ * s.speed / length : 1;
      x_ = s.x0 + t * (s.x1 - s.x0), y_ = s.y0 + t * (s.y1 - s.y0);
      return;
    }
    seconds -= left;
    into_ = 0;
    x_ = s.x1, y_ = s.y1;
    if (s.lit) {
      const RuidaCut cut{s.x0 / 1000, s.y0 / 1000, s.x1 / 1000, s.y1 / 1000, s.power};
      cuts_.push_back(cut);
      if (options_.cutFinished) options_.cutFinished({cut.x0, cut.y0, cut.x1, cut.y1});
    }
    ++next_;
  }
  if (next_ == queue_.size()) {
    setLaser(false);
    queue_.clear(), next_ = 0;
    if (jobEnded_) jobStarted_ = jobEnded_ = false;
  }
}

void RuidaSimulator::setLaser(bool lit) {
  if (laserOn_.exchange(lit) != lit && options_.laserChanged) options_.laserChanged(lit);
}

int64_t RuidaSimulator::memory(uint16_t address) const {
  switch (address) {
    case ruida::kMemoryStatus:
      return (jobStarted_ && options_.reportsJobs ? ruida::kStatusJobRuns : 0) |
             (next_ < queue_.size() && !paused_ ? ruida::kStatusMoving : 0);
    case ruida::kMemoryX:
      return std::lround(x_);
    case ruida::kMemoryY:
      return std::lround(y_);
    case ruida::kMemoryBedX:
      return std::lround(options_.bedWidth * 1000);
    case ruida::kMemoryBedY:
      return std::lround(options_.bedHeight * 1000);
    case ruida::kMemoryCardId:
      return 0x65106510;  // an RDC6442S
    default:
      return 0;
  }
}

}  // namespace rotafab::devices::sim
