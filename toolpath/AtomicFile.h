#pragma once
// Writes an output file atomically, as docs/CONTRACT.md, "Command line",
// demands ("no partial output: its files are written whole or not at all"):
// the bytes go to a temporary file in the target's own folder (so that the
// rename cannot cross file systems), which is flushed to disk (fsync) and then
// renamed over the target. Readers see either the old file or the complete new
// one, never a half-written one. On any failure the temporary file is removed,
// the target is left as it was, and a std::runtime_error says in one line
// which file could not be written and why.
//
// The new file gets the permissions of a normal new file (0666 minus the
// umask), not those of the file it replaces.

#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace rotafab::jobs {

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// Collects what `write` puts on the stream, then writes it as above. An
// exception thrown by `write` propagates unchanged, and nothing is created.
void writeFileAtomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

}  // namespace rotafab::jobs
