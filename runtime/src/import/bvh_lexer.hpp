// A cursor over BVH text that hands out whitespace-separated tokens while
// counting 1-based lines. It works on a string_view (no copies, no iostreams)
// because the benchmark sets push ~55 million numbers through it. CR, LF and
// CRLF all end a line, so mixed line endings need no special case.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace mmvk::detail {

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }
inline bool is_line_break(char c) { return c == '\n' || c == '\r'; }
inline bool is_space(char c) { return is_blank(c) || is_line_break(c); }

// Parses a whole token as a finite float or double. Accepts what strtof
// accepts for decimal numbers (".0083333", "-2.47945e-15", "1.", a leading
// '+'), but not "inf", "nan" or hexadecimal floats.
template <class Real>
std::optional<Real> parse_real(std::string_view token) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  const bool plus = first != last && *first == '+';
  if (plus) ++first;
  if (first == last) return std::nullopt;
  const char lead = !plus && *first == '-' && first + 1 != last ? first[1] : *first;
  if (!((lead >= '0' && lead <= '9') || lead == '.')) return std::nullopt;  // rejects inf/nan
  Real value = 0;
  const auto [end, error] = std::from_chars(first, last, value, std::chars_format::general);
  if (error != std::errc{} || end != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

inline std::optional<float> parse_float(std::string_view token) { return parse_real<float>(token); }
inline std::optional<double> parse_double(std::string_view token) { return parse_real<double>(token); }

// Clinger's fast path for the common case: a plain decimal ("-375.227000",
// no exponent) with at most 7 significant digits (trailing fraction zeros do
// not count) is m / 10^k with m < 2^24 and k <= 10, both exactly
// representable in float, so one IEEE division is correctly rounded: the same
// float that from_chars returns. Returns false (leaving the number to
// from_chars) for anything else.
inline bool parse_short_decimal(const char* p, const char* end, float* value, const char** stop) {
  static constexpr float kPowersOf10[] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 1e7f, 1e8f, 1e9f, 1e10f};
  const bool negative = p != end && *p == '-';
  if (negative) ++p;
  std::uint32_t mantissa = 0;
  int significant = 0;
  int pending_zeros = 0;  // zeros after the last non-zero digit, not yet in `mantissa`
  int fraction_digits = 0;
  bool dot = false;
  bool any_digit = false;
  const auto flush_zeros = [&]() {
    significant += pending_zeros;
    if (significant > 7) return false;
    for (; pending_zeros > 0; --pending_zeros) mantissa *= 10;
    return true;
  };
  for (; p != end; ++p) {
    const char c = *p;
    if (c >= '0' && c <= '9') {
      any_digit = true;
      if (dot) ++fraction_digits;
      if (c == '0') {
        if (mantissa != 0) ++pending_zeros;  // leading zeros are not significant
        continue;
      }
      if (!flush_zeros() || ++significant > 7) return false;
      mantissa = mantissa * 10 + static_cast<std::uint32_t>(c - '0');
    } else if (c == '.' && !dot) {
      if (!flush_zeros()) return false;  // "1200." keeps its integer zeros
      dot = true;
    } else {
      break;
    }
  }
  if (!any_digit) return false;
  if (p != end && (*p == 'e' || *p == 'E')) return false;
  if (dot) {
    fraction_digits -= pending_zeros;  // "88.510500" is 885105 / 10^4
  } else if (!flush_zeros()) {
    return false;  // "1200" is 1200
  }
  if (fraction_digits > 10) return false;
  const float magnitude = static_cast<float>(mantissa) / kPowersOf10[fraction_digits];
  *value = negative ? -magnitude : magnitude;
  *stop = p;
  return true;
}

class BvhCursor {
 public:
  explicit BvhCursor(std::string_view text) : text_(text) {
    // A UTF-8 byte order mark is not content.
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
  }

  // Line of the next unread character (1-based).
  int line() const { return line_; }
  bool at_end() const { return pos_ >= text_.size(); }

  // Skips blanks and line breaks; returns the next token, or empty at the end.
  // `token_line` receives the token's line.
  std::string_view next_token(int* token_line = nullptr) {
    skip_space();
    if (token_line) *token_line = line_;
    return read_token();
  }

  // The next token without consuming it.
  std::string_view peek_token(int* token_line = nullptr) {
    const std::size_t saved_pos = pos_;
    const int saved_line = line_;
    std::string_view token = next_token(token_line);
    pos_ = saved_pos;
    line_ = saved_line;
    return token;
  }

  // Next token on the current line only; empty when the line has no more.
  std::string_view next_token_on_line() {
    skip_blanks();
    return read_token();
  }

  // The rest of the current line with surrounding blanks trimmed; consumes it
  // but not the line break.
  std::string_view rest_of_line() {
    skip_blanks();
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && !is_line_break(text_[pos_])) ++pos_;
    std::size_t end = pos_;
    while (end > begin && is_blank(text_[end - 1])) --end;
    return text_.substr(begin, end - begin);
  }

  // Consumes blanks and at most one line break. Returns false when something
  // other than blanks precedes the line break.
  bool finish_line() {
    skip_blanks();
    if (pos_ >= text_.size()) return true;
    if (!is_line_break(text_[pos_])) return false;
    consume_line_break();
    return true;
  }

  // Skips blank lines and leading blanks; true if a non-empty line follows.
  bool skip_empty_lines() {
    skip_space();
    return pos_ < text_.size();
  }

  // Reads the numbers of one motion line into `out` (at most `capacity`
  // values; more are counted but not stored). Stops at the line break, which
  // it consumes. Returns the number of values seen; on a token that is not a
  // number, returns -1 and sets `bad_token`.
  int read_number_line(float* out, int capacity, std::string_view* bad_token) {
    int count = 0;
    const char* const end = text_.data() + text_.size();
    for (;;) {
      skip_blanks();
      if (pos_ >= text_.size()) return count;
      if (is_line_break(text_[pos_])) {
        consume_line_break();
        return count;
      }
      // Hot path: parse in place, then check that the number is the whole
      // token. Only a leading digit, '.', '-' or '+' may start a number
      // (from_chars would also take "inf" and "nan").
      const char* first = text_.data() + pos_;
      const bool plus = *first == '+' && first + 1 != end;
      if (plus) ++first;
      const char lead = !plus && *first == '-' && first + 1 != end ? first[1] : *first;
      float value = 0.0f;
      const char* stop = first;
      if (((lead >= '0' && lead <= '9') || lead == '.') && !parse_short_decimal(first, end, &value, &stop)) {
        const auto result = std::from_chars(first, end, value, std::chars_format::general);
        stop = result.ec == std::errc{} && std::isfinite(value) ? result.ptr : first;
      }
      if (stop == first || (stop != end && !is_space(*stop))) {
        *bad_token = read_token();
        return -1;
      }
      pos_ = static_cast<std::size_t>(stop - text_.data());
      if (count < capacity) out[count] = value;
      ++count;
    }
  }

  std::size_t remaining_bytes() const { return pos_ < text_.size() ? text_.size() - pos_ : 0; }

 private:
  void skip_blanks() {
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
  }
  void consume_line_break() {
    if (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
    ++pos_;
    ++line_;
  }
  void skip_space() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (is_blank(c)) {
        ++pos_;
      } else if (is_line_break(c)) {
        consume_line_break();
      } else {
        break;
      }
    }
  }
  std::string_view read_token() {
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    return text_.substr(begin, pos_ - begin);
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

}  // namespace mmvk::detail
