#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

void Service::Impl::leaseRenewed(Clock::time_point sent) {
  lastBeat = sent;
  const auto margin = std::chrono::duration<double>(config.lease * 0.8);
  safeUntil = std::chrono::duration_cast<std::chrono::nanoseconds>(
                  (sent + std::chrono::duration_cast<Clock::duration>(margin)).time_since_epoch())
                  .count();
}

void Service::Impl::watchLease() {
  while (watching) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
    if (now <= safeUntil || leaseLost.exchange(true)) continue;
    std::lock_guard lock(heldMutex);
    log->error("host {}: its lease on the job store was not renewed in time: stopping its {} cut{} and {} plan{}",
               config.host, heldCuts.size(), heldCuts.size() == 1 ? "" : "s", heldPlans.size(),
               heldPlans.size() == 1 ? "" : "s");
    for (auto& [id, control] : heldCuts) {
      control->shutdown = true;
      control->cancel.cancel();
    }
    for (auto& [id, cancel] : heldPlans) cancel->cancel();
    onStrand([this] { fence("its lease was not renewed in time"); });
  }
}

void Service::Impl::open() {
  std::error_code error;
  fs::create_directories(config.stateDir, error);
  if (error) {
    throw StoreError(
        fmt::format("{}: cannot create the state directory: {}", config.stateDir.string(), error.message()));
  }
  // Before the store is opened (its start writes), room for what must be written.
  reserve.emplace(config.stateDir / "rotafabd.reserve");
  if (!reserve->enough() || !reserve->hold()) {
    reserve->release();
    diskFull = true;
    log->error(
        "{}: the daemon starts to answer and to cancel, with what room there is; nothing new is taken on "
        "until there is room again",
        kDiskFull);
  }
  store = config.store.empty() ? openSqliteStore(config.stateDir / "jobs.sqlite3") : openPostgresStore(config.store);
  spool = std::make_unique<Spool>(config.spool.empty() ? config.stateDir / "spool" : config.spool,
                                  store->shared() ? config.host : "");
  catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  const std::string where = config.file.empty() ? std::string("the default configuration") : config.file.string();
  for (const DeviceConfig& deviceConfig : config.devices) {
    Device device;
    device.config = deviceConfig;
    devices::ParsedUri uri;
    try {
      uri = devices::parseDeviceUri(deviceConfig.uri);
    } catch (const std::invalid_argument& bad) {
      throw ConfigError(fmt::format("{}: device {}: {}", where, deviceConfig.name, bad.what()));
    }
    try {
      if (deviceConfig.machine.empty()) {
        const auto machine = profiles::firstMachineFor(catalogue, uri.driver->name());
        if (!machine) {
          throw ConfigError(fmt::format("{}: device {}: no machine profile for the {} driver; give machine:", where,
                                        deviceConfig.name, uri.driver->name()));
        }
        device.machine = *machine;
      } else {
        device.machine = profiles::findMachine(catalogue, deviceConfig.machine);
      }
      device.material = profiles::findMaterial(catalogue, deviceConfig.material);
    } catch (const profiles::ProfileError& bad) {
      throw ConfigError(fmt::format("{}: device {}: {}", where, deviceConfig.name, bad.what()));
    }
    if (device.machine.driver != uri.driver->name()) {
      throw ConfigError(fmt::format("{}: device {}: machine {} is driven by {}, not by {}'s {} driver", where,
                                    deviceConfig.name, device.machine.name, device.machine.driver, deviceConfig.uri,
                                    uri.driver->name()));
    }
    devices.push_back(std::move(device));
  }
}

std::pair<JobState, std::string> Service::Impl::released(const JobRecord& job, const std::string& who) {
  if (holdsDevice(job.state)) {
    return {JobState::Interrupted, fmt::format("{} stopped while it cut, {}; check the machine, then {}", who,
                                               sheetWhere(job.sheet, job.sheets, job.stroke, job.strokes),
                                               goOnSaid(std::max(1, job.sheet), job.stroke, job.strokes))};
  }
  return {JobState::Queued, fmt::format("{} stopped while it planned; it is planned again", who)};
}

DeviceRecord Service::Impl::deviceRecord(const Device& device) const {
  DeviceRecord record;
  record.name = device.config.name;
  record.host = config.host;
  record.machine = device.machine.name;
  record.material = device.material.name;
  record.uri = device.config.uri;
  record.autoStart = device.config.autoStart;
  record.state = device.state;
  record.message = device.message;
  record.job = device.job;
  return record;
}

void Service::Impl::joinStore(double wait) {
  HostRecord me;
  me.name = config.host;
  for (const std::string& address : config.listen) {
    if (address.starts_with("tcp://")) {
      me.address = "http://" + address.substr(6);
      break;
    }
  }
  std::vector<DeviceRecord> records;
  for (const Device& device : devices) records.push_back(deviceRecord(device));
  const auto sent = Clock::now();
  const std::vector<JobRecord> left =
      store->join(me, records, config.lease, wait,
                  [](const JobRecord& job, const HostRecord&) { return released(job, "the daemon"); });
  joined = true;
  if (store->shared()) {
    leaseRenewed(sent);
    leaseLost = false;
  }
  for (const JobRecord& job : left) {
    if (job.state == JobState::Interrupted) log->warn("job {}: {}", job.id, job.message);
    jobChanged(job);
  }
  if (store->shared()) refreshOthers();
}

void Service::Impl::join() {
  joinStore(config.lease + 2);
  std::set<std::string> named;
  store->eachJob([&](const JobRecord& job) { named.insert(job.spool); });
  if (const size_t removed = spool->removeOrphans(named); removed > 0) {
    log->info("removed {} spool folder{} that no job names (left by a stop mid-submission)", removed,
              removed == 1 ? "" : "s");
  }
  if (store->shared()) {
    log->info("host {} on the shared job store, lease {:g} s", config.host, config.lease);
    ticker.emplace(strand);
    tick();
    watching = true;
    watchdog = std::thread([this] { watchLease(); });
  }
}

void Service::Impl::tick() {
  ticker->expires_after(std::chrono::milliseconds(500));
  ticker->async_wait([this](const boost::system::error_code& error) {
    if (error) return;
    // The heartbeat first, by the clock; and on until a stop has stopped every cut.
    if (Clock::now() - lastBeat >= std::chrono::duration<double>(config.lease / 5)) beat();
    if (stopping) {
      if (!cuts.empty() || !planning.empty()) tick();
      return;
    }
    if (joined && !leaseLost) {
      try {
        serveRequests();
      } catch (const std::exception& failure) {
        log->error("{}", failure.what());
      }
    }
    pump();
    tick();
  });
}

void Service::Impl::beat() {
  try {
    if (!joined) {
      // Again, after its lease ran out, once every cut and plan it had has
      // stopped; without waiting (a refusal is tried again at the next beat).
      if (stopping || !cuts.empty() || !planning.empty()) return;
      joinStore(0);
      log->info("host {} joined the shared job store again", config.host);
      return;
    }
    const auto sent = Clock::now();
    if (!store->heartbeat(config.lease)) {
      fence("its lease ran out and another host released its jobs");
      return;
    }
    leaseRenewed(sent);
    const std::vector<JobRecord> taken = store->releaseLapsedHosts([](const JobRecord& job, const HostRecord& host) {
      return released(job, fmt::format("host {} (its last heartbeat {})", host.name, isoTime(host.seen)));
    });
    for (const JobRecord& job : taken) {
      log->warn("job {}: {}", job.id, job.message);
      jobChanged(job);
    }
    refreshOthers();
  } catch (const std::exception& error) {
    log->error("{}", error.what());  // (the watchdog stops the cuts if the lease is not renewed in time)
  }
}

void Service::Impl::fence(const std::string& why) {
  if (!joined) return;
  log->error("host {}: {}: stopping its cuts and plans", config.host, why);
  joined = false;
  leaseLost = true;
  for (auto& [id, plan] : planning) plan.cancel->cancel();
  for (auto& [id, cut] : cuts) stopCutByItself(*cut, "");
}

void Service::Impl::serveRequests() {
  for (const ActionRequest& request : store->takeRequests()) {
    const json arguments = json::parse(request.arguments, nullptr, false);
    // (Checked again here: the store is an edge too, for what another host's daemon left in it.)
    const Reply reply = guarded([&] {
      return act(request.job, request.action,
                 checkedActionArguments(request.action, arguments.is_discarded() ? json::object() : arguments),
                 request.who);
    });
    if (reply.status >= 400) {
      const std::string why = reply.body.value("error", "refused");
      log->warn("job {}: {}'s {} through another host: {}", request.job, request.who, request.action, why);
      store->addEvent(request.job, "refused", fmt::format("{}'s {}: {}", request.who, request.action, why));
    }
  }
}

void Service::Impl::refreshOthers() {
  std::vector<Target> found;
  for (const DeviceRecord& device : store->devices()) {
    if (device.host == config.host || device.state == "gone") continue;
    try {
      found.push_back({device.name, device.host, profiles::findMachine(catalogue, device.machine),
                       profiles::findMaterial(catalogue, device.material)});
    } catch (const profiles::ProfileError&) {
      // A profile this host does not have: it cannot plan for that device.
    }
  }
  std::lock_guard lock(othersMutex);
  others = std::move(found);
}

std::string Service::Impl::hostAddressSaid(const std::string& host) {
  try {
    for (const HostRecord& record : store->hosts()) {
      if (record.name == host && !record.address.empty()) return " (" + record.address + ")";
    }
  } catch (const std::exception&) {
  }
  return "";
}

void Service::Impl::checkDevices() {
  for (size_t index = 0; index < devices.size(); ++index) {
    const std::string uri = devices[index].config.uri;
    const profiles::MachineProfile machine = devices[index].machine;
    checks.emplace_back([this, index, uri, machine] {
      std::string state = "idle", message;
      try {
        devices::ParsedUri parsed = devices::parseDeviceUri(uri);
        auto device = parsed.driver->open(*parsed.address, devices::deviceSetupFor(machine));
        const std::string identity = device->connect();
        const bool off = device->stopSafely();
        device->disconnect();
        message = off ? fmt::format("{}; stopped, laser off confirmed", identity)
                      : fmt::format("{}; stopped, but the controller did not confirm its laser off", identity);
      } catch (const devices::DeviceFault& fault) {
        state = "offline";
        message = fault.what();
      } catch (const std::exception& error) {
        state = "offline";
        message = error.what();
      }
      onStrand([this, index, state, message] {
        Device& device = devices[index];
        if (device.state == "checking") device.state = state;
        if (state == "offline") device.message = message;
        device.checked = message;
        if (state == "offline") {
          log->warn("device {}: offline: {}", device.config.name, message);
        } else {
          log->info("device {}: {}", device.config.name, message);
        }
        store->addEvent(std::nullopt, "device", fmt::format("{}: {}: {}", device.config.name, state, message));
        deviceChanged(device);
        pump();
      });
    });
  }
}

}  // namespace rotafab::service
