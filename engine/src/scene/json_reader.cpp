#include "scene/json_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include "sph2d/scene.hpp"

namespace sph2d {
namespace {

constexpr int kMaxDepth = 200;

/// Length of the UTF-8 sequence starting at s[i] (1..4), or 0 when the bytes
/// there are not valid UTF-8 (overlong forms, surrogates and code points
/// above U+10FFFF included).
std::size_t utf8Length(const std::string& s, std::size_t i) {
  const auto b = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
  const unsigned c = b(i);
  if (c < 0x80) return 1;
  const auto cont = [&](std::size_t k) { return (b(k) & 0xC0u) == 0x80u; };
  if (c >= 0xC2 && c <= 0xDF) return cont(i + 1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    const unsigned c1 = b(i + 1);
    if (c == 0xE0 && c1 < 0xA0) return 0;   // overlong
    if (c == 0xED && c1 >= 0xA0) return 0;  // UTF-16 surrogate
    return cont(i + 1) && cont(i + 2) ? 3 : 0;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    const unsigned c1 = b(i + 1);
    if (c == 0xF0 && c1 < 0x90) return 0;   // overlong
    if (c == 0xF4 && c1 >= 0x90) return 0;  // above U+10FFFF
    return cont(i + 1) && cont(i + 2) && cont(i + 3) ? 4 : 0;
  }
  return 0;
}

void appendUtf8(std::string& out, unsigned cp) {
  if (cp < 0x80) {
    out += char(cp);
  } else if (cp < 0x800) {
    out += char(0xC0 | (cp >> 6));
    out += char(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += char(0xE0 | (cp >> 12));
    out += char(0x80 | ((cp >> 6) & 0x3F));
    out += char(0x80 | (cp & 0x3F));
  } else {
    out += char(0xF0 | (cp >> 18));
    out += char(0x80 | ((cp >> 12) & 0x3F));
    out += char(0x80 | ((cp >> 6) & 0x3F));
    out += char(0x80 | (cp & 0x3F));
  }
}

std::string hexByte(unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", unsigned(c));
  return buf;
}

class Parser {
 public:
  Parser(const std::string& text, const std::string& file, JsonDoc& doc) : s_(text), file_(file), doc_(doc) {
    lineStart_.push_back(0);
    for (std::size_t k = 0; k < s_.size(); ++k)
      if (s_[k] == '\n') lineStart_.push_back(k + 1);
  }

  void run() {
    // A UTF-8 byte order mark (some editors write one) is not part of the JSON.
    if (s_.compare(0, 3, "\xEF\xBB\xBF") == 0) i_ = 3;
    checkUtf8();
    skipWs();
    if (i_ >= s_.size()) {
      i_ = 0;
      fail(s_.size() == 0 ? "the file is empty; a scene is a JSON object such as {}"
                          : "the file holds only whitespace; a scene is a JSON object such as {}");
    }
    mark("", i_);
    doc_.root = value("");
    skipWs();
    if (i_ < s_.size()) fail("unexpected text after the JSON value (one scene object per file)");
  }

 private:
  [[noreturn]] void fail(const std::string& msg) { failAt(i_, msg); }
  [[noreturn]] void failAt(std::size_t pos, const std::string& msg) {
    auto lc = lineCol(pos);
    throw SceneError(file_, lc.first, lc.second, "", "invalid JSON: " + msg);
  }
  /// 1-based line and column (in bytes; the BOM counts as no column) of byte `pos`.
  std::pair<int, int> lineCol(std::size_t pos) const {
    pos = std::min(pos, s_.size());
    const auto it = std::upper_bound(lineStart_.begin(), lineStart_.end(), pos);
    const std::size_t line = std::size_t(it - lineStart_.begin());  // >= 1
    std::size_t start = *(it - 1);
    if (start == 0 && s_.compare(0, 3, "\xEF\xBB\xBF") == 0 && pos >= 3) start = 3;
    return {int(std::min<std::size_t>(line, 1u << 30)), int(std::min<std::size_t>(pos - start + 1, 1u << 30))};
  }
  void checkUtf8() {
    for (std::size_t k = i_; k < s_.size();) {
      const std::size_t n = utf8Length(s_, k);
      if (n == 0)
        failAt(k, "byte " + hexByte(static_cast<unsigned char>(s_[k])) +
                      " is not valid UTF-8; scene files are UTF-8 text (save the file as UTF-8)");
      k += n;
    }
  }
  void skipWs() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  void mark(const std::string& path, std::size_t pos) {
    if (!doc_.where.count(path)) doc_.where[path] = lineCol(pos);
  }
  /// Says what the character at i_ is, with a hint for the usual mistakes.
  [[noreturn]] void unexpected(const std::string& expected) {
    const unsigned char c = static_cast<unsigned char>(s_[i_]);
    std::string what;
    if (c < 0x20 || c == 0x7F) {
      what = "control character " + hexByte(c);
    } else if (c < 0x80) {
      what = std::string("character '") + char(c) + "'";
    } else {
      what = "character '" + s_.substr(i_, utf8Length(s_, i_)) + "'";
    }
    std::string hint;
    const auto at = [&](const char* w) { return s_.compare(i_, std::char_traits<char>::length(w), w) == 0; };
    if (at("NaN") || at("nan") || at("Infinity") || at("inf") || at("-Infinity") || at("-inf"))
      hint = "; NaN and Infinity are not JSON numbers (write a finite number)";
    else if (at("//") || at("/*") || c == '#')
      hint = "; JSON has no comments";
    else if (c == '\'')
      hint = "; JSON strings and keys use double quotes";
    else if (at("\xE2\x80\x9C") || at("\xE2\x80\x9D"))
      hint = "; typographic quotes: use plain double quotes \"";
    else if (c == '+' || c == '.')
      hint = "; a JSON number starts with '-' or a digit (write 0.5, not .5 or +0.5)";
    fail("unexpected " + what + (expected.empty() ? "" : ", expected " + expected) + hint);
  }
  nlohmann::json value(const std::string& path) {
    if (++depth_ > kMaxDepth) fail("nested deeper than " + std::to_string(kMaxDepth) + " levels");
    skipWs();
    if (i_ >= s_.size()) fail("unexpected end of file, expected a value");
    nlohmann::json out;
    const char c = s_[i_];
    if (c == '{') {
      out = object(path);
    } else if (c == '[') {
      out = array(path);
    } else if (c == '"') {
      out = string();
    } else if (c == '-' && (s_.compare(i_, 4, "-inf") == 0 || s_.compare(i_, 4, "-Inf") == 0)) {
      unexpected("a value");
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      out = number();
    } else if (c == 't' || c == 'f' || c == 'n') {
      out = literal();
    } else {
      unexpected("a value");
    }
    --depth_;
    return out;
  }
  nlohmann::json object(const std::string& path) {
    nlohmann::json out = nlohmann::json::object();
    ++i_;
    skipWs();
    if (i_ < s_.size() && s_[i_] == '}') {
      ++i_;
      return out;
    }
    for (;;) {
      skipWs();
      if (i_ >= s_.size()) fail("unexpected end of file inside an object, expected a key or '}'");
      if (s_[i_] != '"') {
        if (s_[i_] == '}') fail("trailing comma before '}'");
        unexpected("a key in double quotes");
      }
      const std::size_t keyPos = i_;
      std::string key = string();
      const std::string sub = path.empty() ? key : path + "." + key;
      if (out.contains(key)) failAt(keyPos, "duplicate key '" + key + "'");
      mark(sub, keyPos);
      skipWs();
      if (i_ >= s_.size()) fail("unexpected end of file, expected ':' after key '" + key + "'");
      if (s_[i_] != ':') unexpected("':' after key '" + key + "'");
      ++i_;
      out[key] = value(sub);
      skipWs();
      if (i_ >= s_.size()) fail("unexpected end of file inside an object, expected ',' or '}'");
      if (s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (s_[i_] == '}') {
        ++i_;
        return out;
      }
      unexpected("',' or '}' in an object");
    }
  }
  nlohmann::json array(const std::string& path) {
    nlohmann::json out = nlohmann::json::array();
    ++i_;
    skipWs();
    if (i_ < s_.size() && s_[i_] == ']') {
      ++i_;
      return out;
    }
    for (std::size_t k = 0;; ++k) {
      skipWs();
      if (i_ < s_.size() && s_[i_] == ']') fail("trailing comma before ']'");
      const std::string sub = path + "[" + std::to_string(k) + "]";
      mark(sub, i_);
      out.push_back(value(sub));
      skipWs();
      if (i_ >= s_.size()) fail("unexpected end of file inside an array, expected ',' or ']'");
      if (s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (s_[i_] == ']') {
        ++i_;
        return out;
      }
      unexpected("',' or ']' in an array");
    }
  }
  unsigned hex4() {
    if (i_ + 4 > s_.size()) fail("short \\u escape (expected 4 hex digits)");
    unsigned cp = 0;
    for (int k = 0; k < 4; ++k) {
      const char h = s_[i_];
      cp <<= 4;
      if (h >= '0' && h <= '9')
        cp |= unsigned(h - '0');
      else if (h >= 'a' && h <= 'f')
        cp |= unsigned(h - 'a' + 10);
      else if (h >= 'A' && h <= 'F')
        cp |= unsigned(h - 'A' + 10);
      else
        fail("bad hex digit in a \\u escape");
      ++i_;
    }
    return cp;
  }
  std::string string() {
    const std::size_t open = i_;
    ++i_;  // opening quote
    std::string out;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '"') {
        ++i_;
        return out;
      }
      if (static_cast<unsigned char>(c) < 0x20) {
        if (c == '\n') failAt(open, "unterminated string (a string ends on its line)");
        fail("control character " + hexByte(static_cast<unsigned char>(c)) +
             " inside a string (write it as an escape)");
      }
      ++i_;
      if (c != '\\') {
        out += c;  // the text is valid UTF-8 (checked before parsing)
        continue;
      }
      if (i_ >= s_.size()) break;
      const char e = s_[i_];
      switch (e) {
        case '"':
          out += '"';
          break;
        case '\\':
          out += '\\';
          break;
        case '/':
          out += '/';
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          const std::size_t esc = i_ - 1;
          ++i_;
          unsigned cp = hex4();
          if (cp >= 0xDC00 && cp <= 0xDFFF) failAt(esc, "lone UTF-16 low surrogate in a \\u escape");
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (s_.compare(i_, 2, "\\u") != 0) failAt(esc, "UTF-16 high surrogate not followed by a low surrogate");
            i_ += 2;
            const unsigned lo = hex4();
            if (lo < 0xDC00 || lo > 0xDFFF) failAt(esc, "UTF-16 high surrogate not followed by a low surrogate");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
          }
          if (cp == 0) failAt(esc, "\\u0000 (a NUL character) is not allowed in scene strings");
          appendUtf8(out, cp);
          continue;
        }
        default:
          fail(std::string("bad escape '\\") +
               (static_cast<unsigned char>(e) >= 0x20 && static_cast<unsigned char>(e) < 0x7F
                    ? std::string(1, e)
                    : hexByte(static_cast<unsigned char>(e))) +
               "'");
      }
      ++i_;
    }
    failAt(open, "unterminated string");
  }
  nlohmann::json literal() {
    auto take = [&](const char* word) {
      const std::string w(word);
      if (s_.compare(i_, w.size(), w) == 0) {
        i_ += w.size();
        return true;
      }
      return false;
    };
    if (take("true")) return true;
    if (take("false")) return false;
    if (take("null")) return nullptr;
    unexpected("true, false or null");
  }
  nlohmann::json number() {
    const std::size_t start = i_;
    bool isFloat = false;
    if (s_[i_] == '-') ++i_;
    if (i_ >= s_.size() || !(s_[i_] >= '0' && s_[i_] <= '9')) {
      if (i_ >= s_.size()) fail("unexpected end of file in a number");
      unexpected("a digit");
    }
    if (s_[i_] == '0' && i_ + 1 < s_.size() && s_[i_ + 1] >= '0' && s_[i_ + 1] <= '9') fail("leading zero in a number");
    std::size_t intDigits = 0,
                leadingZeros = 0;  // significant digits before '.', zeros after '.' before the first digit
    while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') {
      if (intDigits > 0 || s_[i_] != '0') ++intDigits;
      ++i_;
    }
    if (i_ < s_.size() && s_[i_] == '.') {
      isFloat = true;
      ++i_;
      if (i_ >= s_.size() || !(s_[i_] >= '0' && s_[i_] <= '9')) fail("expected a digit after '.'");
      bool seen = false;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') {
        if (!seen && s_[i_] == '0')
          ++leadingZeros;
        else
          seen = true;
        ++i_;
      }
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      isFloat = true;
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (i_ >= s_.size() || !(s_[i_] >= '0' && s_[i_] <= '9')) fail("expected a digit in the exponent");
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    }
    const char* b = s_.data() + start;
    const char* e = s_.data() + i_;
    if (!isFloat) {
      long long v = 0;
      const auto r = std::from_chars(b, e, v);
      if (r.ec == std::errc() && r.ptr == e) return v;
    }
    double d = 0;
    const auto r = std::from_chars(b, e, d);  // locale-independent
    if (r.ec == std::errc::result_out_of_range) {
      // Overflow or underflow: estimate the decimal exponent to tell them apart.
      long long exp10 = intDigits > 0 ? (long long)intDigits - 1 : -(long long)leadingZeros - 1;
      const std::string tok(b, e);
      const auto ePos = tok.find_first_of("eE");
      if (ePos != std::string::npos) {
        long long x = 0;
        std::size_t k = ePos + 1;
        const bool neg = k < tok.size() && tok[k] == '-';
        if (k < tok.size() && (tok[k] == '-' || tok[k] == '+')) ++k;
        for (; k < tok.size() && x < 100000000; ++k) x = x * 10 + (tok[k] - '0');
        exp10 += neg ? -x : x;
      }
      if (exp10 >= 0) {
        i_ = start;
        fail("number " + (tok.size() > 40 ? tok.substr(0, 40) + "..." : tok) +
             " is too large (a double holds magnitudes up to about 1.8e308)");
      }
      return tok[0] == '-' ? -0.0 : 0.0;  // underflow: as good as zero
    }
    if (r.ec != std::errc() || r.ptr != e || !std::isfinite(d)) {
      i_ = start;
      fail("cannot read the number");
    }
    return d;
  }

  const std::string& s_;
  const std::string& file_;
  JsonDoc& doc_;
  std::vector<std::size_t> lineStart_;
  std::size_t i_ = 0;
  int depth_ = 0;
};

}  // namespace

JsonDoc parseJsonWithPositions(const std::string& text, const std::string& file) {
  JsonDoc doc;
  Parser(text, file, doc).run();
  return doc;
}

}  // namespace sph2d
