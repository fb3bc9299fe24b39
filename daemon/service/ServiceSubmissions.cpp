#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

void Service::Impl::groupChanged() {
  if (toSync.empty()) return;
  if (beingWritten.load() == 0 || toSync.size() >= kLargestGroup) return syncSubmissions();
  if (groupTimerSet) return;
  groupTimerSet = true;
  groupTimer.expires_after(kGroupWait);
  groupTimer.async_wait([this](const boost::system::error_code& error) {
    groupTimerSet = false;
    if (!error && !toSync.empty()) syncSubmissions();
  });
}

void Service::Impl::syncSubmissions() {
  auto batch = std::move(toSync);
  toSync.clear();
  std::vector<Spool::Entry*> entries;
  for (const auto& pending : batch) entries.push_back(&pending->entry);
  try {
    Spool::Entry::commitAll(entries);
  } catch (const std::exception& error) {
    log->error("submissions refused: {}", error.what());
    for (const auto& pending : batch) {
      pending->done({507, {{"error", fmt::format("the job was not accepted: {}", error.what())}}});
    }
    return;  // the entries go with the batch
  }
  onStrand([this, batch = std::move(batch)] {
    toAdd.insert(toAdd.end(), batch.begin(), batch.end());
    if (toAdd.size() == batch.size()) onStrand([this] { addSubmissions(); });
  });
}

void Service::Impl::addSubmissions() {
  auto batch = std::move(toAdd);
  toAdd.clear();
  const auto refuseAll = [&](int status, const std::string& why) {
    for (const auto& pending : batch) {
      std::error_code ignored;
      fs::remove_all(pending->entry.folder(), ignored);
      pending->done({status, {{"error", why}}});
    }
  };
  if (stopping) return refuseAll(503, "the daemon is stopping");
  std::vector<NewJob> jobs;
  std::vector<std::string> reasons;
  for (const auto& pending : batch) {
    jobs.push_back(pending->job);
    reasons.push_back(fmt::format("submitted by {}", pending->job.owner));
  }
  std::vector<JobRecord> added;
  try {
    added = store->addJobs(jobs, reasons);
  } catch (const StoreError& error) {
    log->error("{}", error.what());
    return refuseAll(507, error.what());
  } catch (const std::exception& error) {
    log->error("{}", error.what());
    return refuseAll(500, error.what());
  }
  for (size_t i = 0; i < added.size(); ++i) {
    log->info(
        "job {}: {} submitted by {}{}", added[i].id, added[i].source, added[i].owner,
        added[i].state == JobState::Queued ? "" : fmt::format("; {}: {}", stateName(added[i].state), added[i].message));
    jobChanged(added[i]);
    batch[i]->done({201, jobJson(added[i])});
  }
  pump();
}

void Service::submit(Submission submission, ReplyHandler done) {
  Impl& impl = *impl_;
  // The bytes go to the spool off the strand; the row once they are durable.
  ++impl.beingWritten;
  asio::post(impl.workers, [&impl, submission = std::move(submission), done = std::move(done)]() mutable {
    // However the submission ends, its entry (if it has one) goes to be
    // synced, and the group commit stops waiting for it.
    struct Written {
      Impl& impl;
      std::shared_ptr<Impl::Pending> pending;
      ~Written() {
        asio::post(impl.syncStrand, [&impl = impl, pending = std::move(pending)] {
          if (pending) impl.toSync.push_back(pending);
          --impl.beingWritten;
          impl.groupChanged();
        });
      }
    } written{impl, nullptr};
    NewJob job;
    job.owner = submission.owner;
    job.device = submission.device;
    job.priority = submission.priority;
    if (submission.options) job.options = jobs::optionsJson(*submission.options).dump();
    std::optional<Spool::Entry> entry;
    Reply refused;
    refused.status = 0;
    try {
      if (impl.stopping) throw ApiError(503, "the daemon is stopping");
      if (impl.diskFull) throw ApiError(507, impl.diskFullRefusal());
      if (!submission.device.empty()) {
        // (Any host's: on a shared store a job may be submitted here for a device of another.)
        std::string why;
        if (!impl.deviceFor(submission.device, job.options, why)) throw ApiError(400, why);
      }
      if (submission.upload) {
        // (Its mesh already written, a piece at a time, as it arrived: UploadForm.h.)
        entry.emplace(std::move(*submission.upload));
        submission.upload.reset();
        job.kind = JobKind::Mesh;
        job.source = submission.fileName;
        if (!submission.options) throw ApiError(400, kNoStructure);
      } else {
        entry.emplace(impl.spool->begin());
        const fs::path path = submission.path;
        std::error_code error;
        if (path.empty() || !path.is_absolute()) {
          throw ApiError(400,
                         fmt::format("path \"{}\": expected an absolute path on the daemon's machine", path.string()));
        }
        if (fs::is_directory(path, error)) {
          if (submission.options) {
            throw ApiError(400, fmt::format("{}: a planned folder is cut as it was made; make options are for a mesh",
                                            path.string()));
          }
          if (!fs::is_regular_file(path / "manifest.json", error)) {
            throw ApiError(400, fmt::format("{}: not an output folder of `rotafab make`: it holds no manifest.json",
                                            path.string()));
          }
          job.kind = JobKind::Planned;
          job.source = shownText(path.string(), 1000);
          // A folder that is not a make output, or whose sheets are wrong, is refused at once.
          std::ifstream manifestFile(path / "manifest.json");
          char first = 0;
          manifestFile >> first;
          if (first != '{') {
            throw ApiError(400, fmt::format("{}: manifest.json is not a manifest (not a JSON object)", path.string()));
          }
          entry->addFolder(path);
          impl.planOnSubmission(job, entry->folder(), path);
        } else if (fs::is_regular_file(path, error)) {
          job.kind = JobKind::Mesh;
          job.source = cleanFileName(path.filename().string());
          if (job.source.empty() || job.source.starts_with("planned")) {
            throw ApiError(400, fmt::format("{}: not a mesh file's name", shownText(path.string(), 1000)));
          }
          if (!submission.options) throw ApiError(400, kNoStructure);
          // Copied a piece at a time: a mesh of any size is never whole in the daemon's memory.
          try {
            entry->copyFile(job.source, path);
          } catch (const std::exception& failed) {
            if (saysDiskFull(failed.what())) throw;
            throw ApiError(400, fmt::format("{}: cannot read the file", shownText(path.string(), 1000)));
          }
        } else {
          throw ApiError(400, fmt::format("{}: no such file or folder on the daemon's machine", path.string()));
        }
      }
      job.spool = entry->name();
    } catch (const ApiError& error) {
      refused = {error.status, {{"error", error.what()}}};
    } catch (const core::UserError& error) {
      refused = {400, {{"error", error.what()}}};
    } catch (const std::exception& error) {
      const std::string what = error.what();
      const bool full = saysDiskFull(what);
      refused = {full ? 507 : 500,
                 {{"error", full ? fmt::format("the spool's disk is full; the job was not accepted ({})", what)
                                 : fmt::format("the job was not accepted: {}", what)}}};
      impl.log->error("submission refused: {}", what);
    }
    if (refused.status != 0) {
      // The half-written entry, or the refused upload, goes before the caller is told.
      entry.reset();
      submission.upload.reset();
      done(refused);
      return;
    }
    // Synced to disk with whatever else came in meanwhile, then added with it.
    written.pending = std::make_shared<Impl::Pending>(Impl::Pending{std::move(*entry), job, std::move(done)});
  });
}

Spool::Entry Service::beginUpload() {
  if (impl_->stopping) throw ApiError(503, "the daemon is stopping");
  if (impl_->diskFull) throw ApiError(507, impl_->diskFullRefusal());
  try {
    return impl_->spool->begin();
  } catch (const std::exception& error) {
    impl_->log->error("an upload cannot be kept: {}", error.what());
    if (saysDiskFull(error.what())) throw ApiError(507, "the spool's disk is full; the job was not accepted");
    throw ApiError(500, "the daemon cannot keep an upload in its spool (its log says why)");
  }
}

}  // namespace rotafab::service
