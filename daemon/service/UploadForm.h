#pragma once
// A submission's multipart form (docs/API.md, "Submitting") read as it
// arrives: the mesh's bytes straight into a file of a new spool entry, the
// small fields (options, device, priority) into texts of at most 64 KiB. An
// upload is never whole in memory: the daemon holds one piece of it at a
// time (HttpServer.cpp reads 64 KiB at a time), whatever its size.
//
// Threads: one at a time (the server's disk thread, piece after piece).

#include <optional>
#include <string>
#include <string_view>

#include "daemon/service/Multipart.h"
#include "daemon/service/Spool.h"
#include "daemon/service/Submission.h"

namespace rotafab::service {

class UploadForm final : private MultipartReader::Parts {
 public:
  static constexpr size_t kLongestField = 64 * 1024;

  UploadForm(Spool::Entry entry, const std::string& boundary);

  // The body's next bytes. Throws ApiError: 400 for a malformed form or an
  // unknown field, 507 when the spool's disk is full.
  void feed(std::string_view bytes);
  // The body has ended: the submission it makes, its entry holding the mesh. Throws ApiError.
  Submission finish(const std::string& owner);

 private:
  void begin(const FormPartHead& head) override;
  void bytes(std::string_view bytes) override;
  void end() override;

  MultipartReader reader_;
  Spool::Entry entry_;
  std::optional<Spool::Entry::File> file_;
  std::string fileName_;
  bool fileDone_ = false;
  // The field being read (a name) and what the form's fields said.
  std::string field_, fieldText_;
  std::optional<std::string> options_, device_, priority_;
};

// Whether a failure's words say that a disk is full (ENOSPC, EDQUOT).
bool saysDiskFull(std::string_view what);

}  // namespace rotafab::service
