#pragma once
// multipart/form-data (RFC 7578; delimiters as RFC 2046, 5.1.1), as
// browsers and `curl -F` send a file with fields: read as it arrives, in
// pieces of any size, holding back no more of it than a delimiter's length,
// so that an upload goes to its file and never whole into memory.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rotafab::service {

// A part's header, as its Content-Disposition says.
struct FormPartHead {
  std::string name;
  std::optional<std::string> fileName;  // a file's part (filename="..."), as sent
};

class MultipartReader {
 public:
  // What is told the parts, in order, as their bytes arrive.
  class Parts {
   public:
    virtual void begin(const FormPartHead& head) = 0;
    virtual void bytes(std::string_view bytes) = 0;  // zero or more times between begin and end
    virtual void end() = 0;

   protected:
    ~Parts() = default;
  };

  static constexpr size_t kMostParts = 64;
  static constexpr size_t kLongestPartHeader = 8 * 1024;

  MultipartReader(const std::string& boundary, Parts& parts);

  // The next bytes of the body. Throws std::invalid_argument saying what is
  // malformed (and whatever `parts` throws).
  void feed(std::string_view bytes);
  // The body has ended: throws std::invalid_argument unless its closing delimiter came.
  void finish() const;
  [[nodiscard]] bool done() const { return state_ == State::Epilogue; }

 private:
  enum class State { Preamble, AfterDelimiter, Headers, Body, Epilogue };
  // Reads what it can of held_; false when it needs more bytes.
  bool step();
  void readHeaders(std::string_view headers);

  std::string first_, delimiter_;  // "--BOUNDARY", and "\r\n--BOUNDARY" between parts
  Parts& parts_;
  State state_ = State::Preamble;
  std::string held_;
  size_t partsSeen_ = 0;
};

// The boundary of a Content-Type "multipart/form-data; boundary=..." (1 to
// 70 characters, RFC 2046), or none.
std::optional<std::string> multipartBoundary(std::string_view contentType);

// A whole body's parts, read at once (the tests, small forms).
struct FormPart {
  std::string name;
  std::optional<std::string> fileName;
  std::string bytes;
};
std::vector<FormPart> parseMultipart(std::string_view body, const std::string& boundary);

}  // namespace rotafab::service
