#include "daemon/service/UploadForm.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "daemon/service/ApiError.h"
#include "daemon/service/ApiInput.h"

namespace rotafab::service {
using nlohmann::json;

bool saysDiskFull(std::string_view what) {
  return what.find(std::strerror(ENOSPC)) != std::string_view::npos ||
         what.find(std::strerror(EDQUOT)) != std::string_view::npos ||
         what.find("disk that holds the job store is full") != std::string_view::npos;
}

UploadForm::UploadForm(Spool::Entry entry, const std::string& boundary)
    : reader_(boundary, *this), entry_(std::move(entry)) {}

void UploadForm::feed(std::string_view bytes) {
  try {
    reader_.feed(bytes);
  } catch (const std::invalid_argument& malformed) {
    throw ApiError(400, fmt::format("malformed multipart body: {}", malformed.what()));
  } catch (const ApiError&) {
    throw;
  } catch (const std::exception& failed) {
    if (saysDiskFull(failed.what())) throw ApiError(507, "the spool's disk is full; the job was not accepted");
    throw ApiError(500, fmt::format("the upload could not be written: {}", failed.what()));
  }
}

void UploadForm::begin(const FormPartHead& head) {
  field_ = head.name;
  fieldText_.clear();
  if (head.name == "file" || head.name == "mesh") {
    if (file_ || fileDone_) throw ApiError(400, "the form has two files; a submission is one mesh");
    if (!head.fileName || head.fileName->empty()) throw ApiError(400, "the file part has no filename");
    fileName_ = cleanFileName(*head.fileName);
    if (fileName_.empty() || fileName_.starts_with("planned")) {
      throw ApiError(400, fmt::format("\"{}\" is not a mesh file's name", fileName_.empty() ? "" : fileName_));
    }
    file_.emplace(entry_.create(fileName_));
    return;
  }
  if (head.name != "options" && head.name != "device" && head.name != "priority") {
    throw ApiError(
        400, fmt::format("unknown form field \"{}\" (file, options, device, priority)", cleanFileName(head.name)));
  }
}

void UploadForm::bytes(std::string_view bytes) {
  if (file_) return file_->write(bytes);
  if (fieldText_.size() + bytes.size() > kLongestField) {
    throw ApiError(400, fmt::format("{}: longer than {} KiB", field_, kLongestField / 1024));
  }
  fieldText_.append(bytes);
}

void UploadForm::end() {
  if (file_) {
    file_->close();
    file_.reset();
    fileDone_ = true;
    return;
  }
  if (field_ == "options") options_ = fieldText_;
  if (field_ == "device") device_ = fieldText_;
  if (field_ == "priority") priority_ = fieldText_;
}

Submission UploadForm::finish(const std::string& owner) {
  try {
    reader_.finish();
  } catch (const std::invalid_argument& malformed) {
    throw ApiError(400, fmt::format("malformed multipart body: {}", malformed.what()));
  }
  if (!fileDone_) throw ApiError(400, "the form has no file part (the mesh, as file=@bunny.obj)");
  Submission submission;
  submission.owner = owner;
  if (options_) {
    const json options = json::parse(*options_, nullptr, false);
    if (options.is_discarded()) throw ApiError(400, "options: not valid JSON");
    submission.options = makeOptionsOf(options);
  }
  if (device_) submission.device = checkedText(json(*device_), "device", 64);
  if (priority_) submission.priority = static_cast<int>(wholeNumber(json(*priority_), kPriorityField));
  submission.fileName = fileName_;
  submission.upload.emplace(std::move(entry_));
  return submission;
}

}  // namespace rotafab::service
