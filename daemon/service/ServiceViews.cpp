#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

namespace {

// The sheets cut whole, as the job's cut left them: those before the one it
// is at, and that one too once its every stroke is cut (a job waiting for
// its next sheet, or stopped at a sheet's end), whatever became of the job since.
int sheetsCut(const JobRecord& job) {
  if (job.state == JobState::Done) return job.sheets;
  if (job.sheet <= 0 || job.state == JobState::Queued || job.state == JobState::Planning ||
      job.state == JobState::Ready) {
    return 0;
  }
  return std::min(job.sheets, job.sheet - 1 + (job.strokes > 0 && job.stroke >= job.strokes ? 1 : 0));
}

// A sheet's toolpath for people (docs/API.md, GET /api/jobs/ID/sheets/N): every
// stroke in the order the laser burns it, so that the stroke a cut's
// progress counts is the stroke at that index; to a thousandth of an inch.
json toolpathJson(const jobs::Toolpath& path) {
  const auto rounded = [](double value) { return std::round(value * 1000) / 1000; };
  json strokes = json::array();
  for (const jobs::ToolpathStroke& stroke : path.strokes) {
    json points = json::array();
    for (const auto& point : stroke.points) points.push_back({rounded(point.x()), rounded(point.y())});
    strokes.push_back({{"operation", profiles::operationName(stroke.operation)},
                       {"pass", stroke.pass},
                       {"power", rounded(stroke.power)},
                       {"points", std::move(points)}});
  }
  return {{"sheet", path.sheet},
          {"width", path.width},
          {"height", path.height},
          {"seconds", std::round(path.seconds * 10) / 10},
          {"burn_length", rounded(path.burnLength)},
          {"travel_length", rounded(path.travelLength)},
          {"strokes", std::move(strokes)}};
}

}  // namespace

std::string isoTime(double unixSeconds) {
  const auto seconds = static_cast<std::time_t>(unixSeconds);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::optional<jobs::MakeOptions> storedOptions(const std::string& stored) {
  if (stored.empty()) return std::nullopt;
  return makeOptionsOf(json::parse(stored, nullptr, false));
}

void Service::Impl::publish(const std::string& type, json data) {
  const ServiceEvent event{type, std::move(data)};
  for (const auto& [id, sink] : subscribers) sink(event);
}

json Service::Impl::deviceJson(const Device& device) const {
  json out{{"name", device.config.name},
           {"host", config.host},
           {"uri", device.config.uri},
           {"machine", device.machine.name},
           {"material", device.material.name},
           {"auto_start", device.config.autoStart},
           {"state", device.state},
           // How its frames light the laser: "laser off", or its machine's marking power.
           {"frame_light", profiles::frameLight(device.machine.framePower)}};
  if (!device.message.empty()) out["message"] = device.message;
  if (!device.checked.empty()) out["checked"] = device.checked;
  out["job"] = device.job ? json(*device.job) : json(nullptr);
  return out;
}

JobRecord Service::Impl::withUnrecorded(JobRecord job) const {
  const auto found = unrecorded.find(job.id);
  if (found == unrecorded.end()) return job;
  for (const Unrecorded& change : found->second) {
    job.state = change.to;
    job.message = change.reason + " (not yet recorded: the disk is full)";
    if (change.change.device) job.device = *change.change.device;
    if (change.change.summary) job.summary = *change.change.summary;
    if (change.change.sheets) job.sheets = *change.change.sheets;
    if (change.change.sheet) job.sheet = *change.change.sheet;
    if (change.change.stroke) job.stroke = *change.change.stroke;
    if (change.change.strokes) job.strokes = *change.change.strokes;
  }
  return job;
}

json Service::Impl::jobJson(const JobRecord& stored) const {
  const JobRecord job = withUnrecorded(stored);
  json out{{"id", job.id},
           {"state", stateName(job.state)},
           {"kind", kindName(job.kind)},
           {"source", job.source},
           {"owner", job.owner},
           {"device", job.device.empty() ? json(nullptr) : json(job.device)},
           {"priority", job.priority},
           {"submitted", isoTime(job.submitted)},
           {"updated", isoTime(job.updated)},
           {"sheets", job.sheets},
           {"sheet", job.sheet},
           {"stroke", job.stroke},
           {"strokes", job.strokes},
           {"sheets_cut", sheetsCut(job)},
           {"message", job.message}};
  out["host"] = job.host.empty() ? json(nullptr) : json(job.host);
  // (As the words of `rotafab make`, as the API has always shown them.)
  try {
    const auto options = storedOptions(job.options);
    out["options"] = options ? json(jobs::optionWords(*options)) : json::array();
  } catch (const ApiError&) {
    out["options"] = json::parse(job.options, nullptr, false);
  }
  if (!job.summary.empty()) out["summary"] = json::parse(job.summary, nullptr, false);
  // A job still to cut for a device no longer configured (nor another host's): said, for it to be moved.
  if (!job.device.empty() && (job.state == JobState::Queued || job.state == JobState::Ready ||
                              job.state == JobState::Interrupted || job.state == JobState::Failed)) {
    std::string why;
    if (!deviceFor(job.device, "", why)) {
      out["device_missing"] = fmt::format("{} is no longer configured (on any running host)", job.device);
    }
  }
  if (const auto p = planning.find(job.id); p != planning.end() && !p->second.progress.is_null()) {
    out["progress"] = p->second.progress;
  }
  if (const auto c = cuts.find(job.id); c != cuts.end()) {
    if (!c->second->progress.is_null()) out["progress"] = c->second->progress;
    out["waiting_for_next"] = c->second->waiting.has_value();
    if (c->second->waiting) out["waiting_for"] = c->second->waitingFor, out["waiting_sheet"] = c->second->sheet;
    if (c->second->frameOnly) out["framing_sheet"] = c->second->sheet;
  }
  return out;
}

void Service::Impl::notify(const JobRecord& job, const std::string& kind, json extra) noexcept {
  if (!notifier) return;
  // (What is told to others never stops what it tells of.)
  try {
    json event = {{"event", kind},
                  {"at", isoTime(job.updated)},
                  {"host", config.host},
                  {"job", job.id},
                  {"source", fs::path(job.source).filename().string()},
                  {"device", job.device},
                  {"state", stateName(job.state)},
                  {"sheet", job.sheet},
                  {"sheets", job.sheets},
                  {"sheets_cut", sheetsCut(job)},
                  {"message", job.message}};
    if (extra.is_object()) event.update(extra);
    notifier->send(std::move(event));
  } catch (const std::exception& error) {
    log->error("job {}: its {} event: {}", job.id, kind, error.what());
  }
}

void Service::Impl::jobChanged(const JobRecord& job) {
  if (!subscribers.empty()) publish("job", jobJson(job));
}

void Service::Impl::deviceChanged(const Device& device) {
  try {
    store->putDevice(deviceRecord(device));
  } catch (const std::exception& error) {
    storeTrouble(fmt::format("device {}", device.config.name), error);
  }
  publish("device", deviceJson(device));
}

void Service::list(ReplyHandler done) {
  impl_->answer(std::move(done), [this] {
    // Written a job at a time: the text, not a tree of every job (10,000 jobs: 6 MB, not 45).
    Reply reply;
    reply.text = R"({"jobs":[)";
    bool first = true;
    impl_->store->eachJob([&](const JobRecord& job) {
      if (!first) reply.text += ',';
      first = false;
      reply.text += impl_->jobJson(job).dump(-1, ' ', false, json::error_handler_t::replace);
    });
    reply.text += "]}\n";
    return reply;
  });
}

void Service::status(JobId id, ReplyHandler done) {
  impl_->answer(std::move(done), [this, id] {
    const JobRecord job = impl_->jobOrThrow(id);
    json out = impl_->jobJson(job);
    json transitions = json::array();
    for (const Transition& t : impl_->store->transitions(id)) {
      transitions.push_back({{"from", t.from ? json(stateName(*t.from)) : json(nullptr)},
                             {"to", stateName(t.to)},
                             {"at", isoTime(t.at)},
                             {"reason", t.reason}});
    }
    out["transitions"] = transitions;
    // What happened within its states, newest last: sheets started, frames, the operator's word.
    json events = json::array();
    for (const Event& event : impl_->store->events(id, 20)) {
      events.push_back({{"at", isoTime(event.at)}, {"kind", event.kind}, {"text", event.text}});
    }
    out["events"] = events;
    return Reply{200, out};
  });
}

void Service::manifest(JobId id, ReplyHandler done) {
  impl_->answer(std::move(done), [this, id] {
    const JobRecord job = impl_->jobOrThrow(id);
    if (job.sheets == 0) {
      throw ApiError(409,
                     fmt::format("job {} is {}: it has no manifest until it is planned", id, stateName(job.state)));
    }
    std::ifstream in(impl_->plannedFolder(job) / "manifest.json");
    json manifest = json::parse(in, nullptr, false);
    if (manifest.is_discarded()) throw ApiError(500, fmt::format("job {}: its manifest.json cannot be read", id));
    return Reply{200, manifest};
  });
}

void Service::file(JobId id, const std::string& name, ReplyHandler done) {
  impl_->answer(std::move(done), [this, id, name] {
    const JobRecord job = impl_->jobOrThrow(id);
    // Only what a planned job's folder holds for people to look at, by its own names.
    static const std::regex kShown(R"((sheet-\d{3,}\.(svg|preview\.svg))|structure\.obj|manifest\.txt|manifest\.json)");
    if (!std::regex_match(name, kShown)) {
      throw ApiError(404, fmt::format("no file {} (sheet-NNN.preview.svg, sheet-NNN.svg, structure.obj, "
                                      "manifest.txt, manifest.json)",
                                      name));
    }
    if (job.sheets == 0) {
      throw ApiError(409, fmt::format("job {} is {}: it has no files until it is planned", id, stateName(job.state)));
    }
    const fs::path path = impl_->plannedFolder(job) / name;
    std::error_code error;
    if (!fs::is_regular_file(path, error)) throw ApiError(404, fmt::format("job {} has no {}", id, name));
    Reply reply;
    reply.file = path;
    return reply;
  });
}

void Service::sheet(JobId id, int sheet, ReplyHandler done) {
  // The job and its device's profiles on the strand; the toolpath, which may
  // take a while on a sheet of thousands of strokes, on the workers.
  impl_->onStrand([this, id, sheet, done = std::move(done)]() mutable {
    std::function<Reply()> work;
    const Reply refused = impl_->guarded([&] {
      const JobRecord job = impl_->jobOrThrow(id);
      if (job.sheets == 0) {
        throw ApiError(409,
                       fmt::format("job {} is {}: it has no sheets until it is planned", id, stateName(job.state)));
      }
      if (sheet < 1 || sheet > job.sheets) {
        throw ApiError(404, fmt::format("job {} has sheets 1 to {}, not {}", id, job.sheets, sheet));
      }
      std::string why;
      const std::optional<Impl::Target> device = impl_->deviceFor(job.device, "", why);
      if (!device) throw ApiError(409, fmt::format("job {} has no device to plan its strokes for", id));
      work = [impl = impl_.get(), folder = impl_->plannedFolder(job), machine = device->machine,
              material = device->material, sheet, id] {
        const std::vector<jobs::JobSheet> drawn = jobs::readJobSheets(folder, std::optional<int>(sheet));
        if (drawn.empty()) throw ApiError(404, fmt::format("job {} has no sheet {}", id, sheet));
        const jobs::Toolpath path = jobs::planToolpath(
            drawn.front().drawing, machine, impl->cuttingMaterial(folder, material), jobs::profileMotion(machine));
        json answer = toolpathJson(path);
        // Each operation in its colour of the machine's table (fig. 65), as the sheet files draw it.
        json colours = json::object();
        for (profiles::Operation operation : profiles::kAllOperations) {
          const profiles::Rgb rgb = machine.settingFor(operation).rgb;
          colours[std::string(profiles::operationName(operation))] =
              fmt::format("#{:02x}{:02x}{:02x}", rgb.r, rgb.g, rgb.b);
        }
        answer["colours"] = std::move(colours);
        return Reply{200, std::move(answer)};
      };
      return Reply{0, nullptr};
    });
    if (refused.status != 0) return done(refused);
    asio::post(impl_->workers, [this, work = std::move(work), done = std::move(done)] { done(impl_->guarded(work)); });
  });
}

void Service::devices(ReplyHandler done) {
  impl_->answer(std::move(done), [this] {
    json all = json::array();
    for (const auto& device : impl_->devices) all.push_back(impl_->deviceJson(device));
    if (!impl_->store->shared()) return Reply{200, {{"devices", all}}};
    // On a shared store, the other hosts' devices as their hosts last said, and the hosts.
    json hosts = json::array();
    std::set<std::string> gone;
    for (const HostRecord& host : impl_->store->hosts()) {
      if (host.gone) gone.insert(host.name);
      json entry{{"name", host.name},
                 {"address", host.address},
                 {"state", host.gone ? "gone" : "up"},
                 {"seen", isoTime(host.seen)}};
      hosts.push_back(std::move(entry));
    }
    for (const DeviceRecord& device : impl_->store->devices()) {
      if (device.host == impl_->config.host) continue;
      json entry{{"name", device.name},
                 {"host", device.host},
                 {"uri", device.uri},
                 {"machine", device.machine},
                 {"material", device.material},
                 {"auto_start", device.autoStart},
                 {"state", gone.contains(device.host) ? "gone" : device.state}};
      if (!device.message.empty()) entry["message"] = device.message;
      entry["job"] = device.job ? json(*device.job) : json(nullptr);
      all.push_back(std::move(entry));
    }
    return Reply{200, {{"devices", all}, {"hosts", hosts}}};
  });
}

}  // namespace rotafab::service
