#include "json_reader.hpp"

#include <cerrno>
#include <cstdlib>

#include "sph2d/scene.hpp"

namespace sph2d {
namespace {

class Parser {
 public:
  Parser(const std::string& text, const std::string& file, JsonDoc& doc) : s_(text), file_(file), doc_(doc) {}

  void run() {
    skipWs();
    doc_.root = value("");
    skipWs();
    if (i_ < s_.size()) fail("unexpected text after the JSON value");
  }

 private:
  [[noreturn]] void fail(const std::string& msg) {
    auto lc = lineCol(i_);
    throw SceneError(file_, lc.first, lc.second, "", "invalid JSON: " + msg);
  }
  std::pair<int, int> lineCol(std::size_t pos) const {
    int line = 1, col = 1;
    for (std::size_t k = 0; k < pos && k < s_.size(); ++k) {
      if (s_[k] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    return {line, col};
  }
  void skipWs() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  void mark(const std::string& path, std::size_t pos) {
    if (!doc_.where.count(path)) doc_.where[path] = lineCol(pos);
  }
  nlohmann::json value(const std::string& path) {
    if (++depth_ > 200) fail("nested deeper than 200 levels");
    skipWs();
    if (i_ >= s_.size()) fail("unexpected end of file");
    nlohmann::json out;
    const char c = s_[i_];
    if (c == '{') {
      out = object(path);
    } else if (c == '[') {
      out = array(path);
    } else if (c == '"') {
      out = string();
    } else if (c == 't' || c == 'f' || c == 'n') {
      out = literal();
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      out = number();
    } else {
      fail(std::string("unexpected character '") + c + "'");
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
      if (i_ >= s_.size() || s_[i_] != '"') fail("expected a key in double quotes");
      const std::size_t keyPos = i_;
      std::string key = string();
      const std::string sub = path.empty() ? key : path + "." + key;
      if (out.contains(key)) {
        i_ = keyPos;
        fail("duplicate key '" + key + "'");
      }
      mark(sub, keyPos);
      skipWs();
      if (i_ >= s_.size() || s_[i_] != ':') fail("expected ':' after key '" + key + "'");
      ++i_;
      out[key] = value(sub);
      skipWs();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == '}') {
        ++i_;
        return out;
      }
      fail("expected ',' or '}' in an object");
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
      const std::string sub = path + "[" + std::to_string(k) + "]";
      mark(sub, i_);
      out.push_back(value(sub));
      skipWs();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == ']') {
        ++i_;
        return out;
      }
      fail("expected ',' or ']' in an array");
    }
  }
  std::string string() {
    ++i_;  // opening quote
    std::string out;
    while (i_ < s_.size()) {
      const char c = s_[i_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) {
        --i_;
        fail("control character inside a string");
      }
      if (c != '\\') {
        out += c;
        continue;
      }
      if (i_ >= s_.size()) break;
      const char e = s_[i_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          if (i_ + 4 > s_.size()) fail("short \\u escape");
          unsigned cp = 0;
          for (int k = 0; k < 4; ++k) {
            const char h = s_[i_++];
            cp <<= 4;
            if (h >= '0' && h <= '9') cp |= unsigned(h - '0');
            else if (h >= 'a' && h <= 'f') cp |= unsigned(h - 'a' + 10);
            else if (h >= 'A' && h <= 'F') cp |= unsigned(h - 'A' + 10);
            else fail("bad hex digit in \\u escape");
          }
          // Scene files are ASCII in practice; encode the BMP code point as UTF-8.
          if (cp < 0x80) {
            out += char(cp);
          } else if (cp < 0x800) {
            out += char(0xC0 | (cp >> 6));
            out += char(0x80 | (cp & 0x3F));
          } else {
            out += char(0xE0 | (cp >> 12));
            out += char(0x80 | ((cp >> 6) & 0x3F));
            out += char(0x80 | (cp & 0x3F));
          }
          break;
        }
        default: --i_; fail(std::string("bad escape '\\") + e + "'");
      }
    }
    fail("unterminated string");
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
    fail("expected true, false or null");
  }
  nlohmann::json number() {
    const std::size_t start = i_;
    bool isFloat = false;
    if (s_[i_] == '-') ++i_;
    if (i_ >= s_.size() || !(s_[i_] >= '0' && s_[i_] <= '9')) fail("expected a digit");
    if (s_[i_] == '0' && i_ + 1 < s_.size() && s_[i_ + 1] >= '0' && s_[i_ + 1] <= '9') fail("leading zero in a number");
    while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    if (i_ < s_.size() && s_[i_] == '.') {
      isFloat = true;
      ++i_;
      if (i_ >= s_.size() || !(s_[i_] >= '0' && s_[i_] <= '9')) fail("expected a digit after '.'");
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      isFloat = true;
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (i_ >= s_.size() || !(s_[i_] >= '0' && s_[i_] <= '9')) fail("expected a digit in the exponent");
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    }
    const std::string tok = s_.substr(start, i_ - start);
    if (!isFloat) {
      errno = 0;
      const long long v = std::strtoll(tok.c_str(), nullptr, 10);
      if (errno == 0) return v;
    }
    const double d = std::strtod(tok.c_str(), nullptr);
    return d;
  }

  const std::string& s_;
  const std::string& file_;
  JsonDoc& doc_;
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
