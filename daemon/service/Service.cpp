#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

void Service::Impl::answer(ReplyHandler done, std::function<Reply()> work) {
  onStrand([this, done = std::move(done), work = std::move(work)] { done(guarded(work)); });
}

Reply Service::Impl::guarded(const std::function<Reply()>& work) {
  try {
    return work();
  } catch (const ApiError& error) {
    json body = error.details.is_object() ? error.details : json::object();
    body["error"] = error.what();
    return {error.status, body};
  } catch (const TransitionRefused& error) {
    return {409, {{"error", error.what()}}};
  } catch (const StoreError& error) {
    log->error("{}", error.what());
    return {507, {{"error", error.what()}}};
  } catch (const std::exception& error) {
    log->error("{}", error.what());
    return {500, {{"error", error.what()}}};
  }
}

auto Service::Impl::deviceNamed(const std::string& name) -> Device* {
  for (Device& device : devices) {
    if (device.config.name == name) return &device;
  }
  return nullptr;
}

std::string Service::Impl::deviceNames() const {
  std::string names;
  for (const Device& device : devices) names += (names.empty() ? "" : ", ") + device.config.name;
  return names;
}

JobRecord Service::Impl::jobOrThrow(JobId id) {
  auto job = store->job(id);
  if (!job) throw ApiError(404, fmt::format("there is no job {}", id));
  return *job;
}

std::string summaryText(const JobRecord& job, const char* key) {
  if (job.summary.empty()) return "";
  const json summary = json::parse(job.summary, nullptr, false);
  if (!summary.is_object() || !summary.contains(key) || !summary[key].is_string()) return "";
  return summary[key].get<std::string>();
}

fs::path Service::Impl::plannedFolder(const JobRecord& job) const {
  const fs::path folder = spool->pathOf(job.spool);
  if (job.kind == JobKind::Planned) return folder;
  // On a shared store each plan has a folder of its own, named in its
  // summary: a plan a stalled host finishes late never overwrites the one
  // made since by another host.
  const std::string name = summaryText(job, "folder");
  if (name.starts_with("planned") && name.find('/') == std::string::npos) return folder / name;
  return folder / "planned";
}

Service::Service(asio::io_context& io, DaemonConfig config, std::shared_ptr<spdlog::logger> log)
    : config_(std::move(config)) {
  impl_ = std::make_unique<Impl>(io, config_, std::move(log));
}

Service::~Service() {
  // The heartbeat's timer is let go, so that the strand's pool can finish.
  std::promise<void> quiet;
  asio::post(impl_->strand, [this, &quiet] {
    impl_->stopping = true;
    if (impl_->ticker) impl_->ticker->cancel();
    impl_->diskTimer.cancel();
    quiet.set_value();
  });
  quiet.get_future().wait();
  impl_->watching = false;
  if (impl_->watchdog.joinable()) impl_->watchdog.join();
  // Whatever is still posted finishes; the planners see their cancel.
  for (auto& [id, planning] : impl_->planning) planning.cancel->cancel();
  for (auto& [id, cut] : impl_->cuts) cut->control->cancel.cancel();
  impl_->planners.join();
  for (std::thread& check : impl_->checks) {
    if (check.joinable()) check.join();
  }
  impl_->workers.join();
  impl_->syncer.join();  // (after the workers, who hand it entries; before the strand it hands rows)
  impl_->state.join();
  for (auto& [id, cut] : impl_->cuts) {
    if (cut->thread.joinable()) cut->thread.join();
  }
}

void Service::start() {
  impl_->open();
  std::promise<void> recovered;
  auto done = recovered.get_future();
  impl_->onStrand([this, &recovered] {
    try {
      impl_->join();
      recovered.set_value();
    } catch (...) {
      recovered.set_exception(std::current_exception());
    }
  });
  done.get();
  impl_->onStrand([this] {
    if (impl_->diskFull) impl_->watchDisk();
    impl_->checkDevices();
    impl_->pump();
  });
}

void Service::act(JobId id, const std::string& action, const json& arguments, const std::string& who,
                  ReplyHandler done) {
  impl_->answer(std::move(done), [this, id, action, arguments, who] { return impl_->act(id, action, arguments, who); });
}

size_t Service::subscribe(std::function<void(const ServiceEvent&)> sink) {
  std::promise<size_t> id;
  auto result = id.get_future();
  impl_->onStrand([this, &id, sink = std::move(sink)]() mutable {
    const size_t next = impl_->nextSubscriber++;
    impl_->subscribers[next] = std::move(sink);
    id.set_value(next);
  });
  return result.get();
}

void Service::unsubscribe(size_t id) {
  impl_->onStrand([this, id] { impl_->subscribers.erase(id); });
}

void Service::shutdown(const std::string& why, std::function<void()> done) {
  impl_->onStrand([this, why, done = std::move(done)]() mutable {
    Impl& impl = *impl_;
    impl.stopping = true;  // (the heartbeat goes on until every cut has stopped; no more claims)
    impl.stopped = std::move(done);
    impl.log->info("stopping ({}): {} cut{} and {} plan{} to stop", why, impl.cuts.size(),
                   impl.cuts.size() == 1 ? "" : "s", impl.planning.size(), impl.planning.size() == 1 ? "" : "s");
    for (auto& [id, planning] : impl.planning) planning.cancel->cancel();
    for (auto& [id, cut] : impl.cuts) Impl::stopCutByItself(*cut, "");
    impl.finishIfStopping();
  });
}

}  // namespace rotafab::service
