#pragma once
// What a request brings, checked where it comes in (docs/SECURITY.md,
// "Inputs"): every number against its range, in one table here (a 400 that
// names the field, never a number wrapped to another); every text without
// control characters; a file's name cleaned before it names a file in the
// spool, a job in the queue or a line of the log.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rotafab::service {

// A whole-number field and the values it may take.
struct NumberField {
  std::string_view name;
  int64_t least, most;
};

// Job numbers as a browser's JavaScript reads them exactly (2^53 - 1).
constexpr int64_t kLargestJobId = 9007199254740991;
constexpr NumberField kPriorityField{"priority", -1000000, 1000000};
constexpr NumberField kFromSheetField{"from_sheet", 1, 1000000};
constexpr NumberField kFromStrokeField{"from_stroke", 1, 100000000};
constexpr NumberField kBeforeField{"before", 1, kLargestJobId};
constexpr NumberField kJobField{"job", 1, kLargestJobId};
constexpr NumberField kSheetField{"sheet", 1, 1000000};

// The value of a JSON number, or of text that is one (a form's field);
// throws ApiError(400) naming the field and its range.
int64_t wholeNumber(const nlohmann::json& value, const NumberField& field);
// The same for text; none when it is not a whole number in range (a path's segment: a 404 for its caller).
std::optional<int64_t> wholeNumberIn(std::string_view text, const NumberField& field);

// ASCII letters in lower case, the rest as it is: header names, media
// types, host names and schemes, which HTTP compares without case.
std::string asciiLower(std::string_view text);

// Text of at most `most` bytes, valid UTF-8, without control characters; throws ApiError(400) naming the field.
std::string checkedText(const nlohmann::json& value, std::string_view field, size_t most = 200);

// Text as the queue, a page or the log may show it: without control
// characters, bidirectional overrides or invisible format characters,
// anything not UTF-8 dropped, at most `most` bytes.
std::string shownText(std::string_view text, size_t most);

// An uploaded file's name as the spool, the queue and the log may use it:
// its last component (after '/' or '\'), without control characters,
// bidirectional overrides or invisible format characters, with anything not
// UTF-8 dropped, at most kLongestFileName bytes (the extension kept). Empty
// when nothing usable is left.
constexpr size_t kLongestFileName = 100;
std::string cleanFileName(std::string_view sent);

// A message for a client with every path under `folders` (the daemon's
// state, spool and page folders) said by its file name alone: a caller
// learns nothing of where the daemon keeps its files.
std::string withoutDaemonPaths(std::string message, const std::vector<std::string>& folders);

// An action's arguments, checked and with only the fields it takes
// (resume: from_sheet; move: before or priority; the others: none).
nlohmann::json checkedActionArguments(std::string_view action, const nlohmann::json& body);

}  // namespace rotafab::service
