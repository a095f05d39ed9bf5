// app/output/manifest_reader.cpp — reading manifest.json back; see manifest_reader.hpp.
//
// Design: every value is read through typed helpers that name the key and the type
// and range wanted, so a malformed manifest is one clean UsageError (exit 2), never
// the JSON library's exception text, a float-to-int overflow or an allocation sized
// by the manifest (the kept frames of a run are counted, not listed).
#include "output/manifest_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "cli.hpp"
#include "sph2d/render/render_env.hpp"

namespace sph2d::cli {

using json = nlohmann::ordered_json;

namespace {

/// What a read wanted: the key (dotted) and the type and range, for the message.
struct Malformed {
  std::string key, want;
};

const json& member(const json& obj, const char* key, const std::string& where, const std::string& want) {
  if (!obj.is_object() || !obj.contains(key)) throw Malformed{where + key, want};
  return obj[key];
}

std::string stringAt(const json& obj, const char* key, const std::string& where) {
  const json& v = member(obj, key, where, "a string");
  if (!v.is_string()) throw Malformed{where + key, "a string"};
  return v.get<std::string>();
}

/// An integer in [lo, hi] (JSON integers only: 1e20 or 2.5 are refused, not converted).
int intAt(const json& obj, const char* key, const std::string& where, long long lo, long long hi) {
  const std::string want = "an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
  const json& v = member(obj, key, where, want);
  long long x = 0;
  if (v.is_number_unsigned()) {
    const auto u = v.get<unsigned long long>();
    if (u > static_cast<unsigned long long>(hi)) throw Malformed{where + key, want};
    x = static_cast<long long>(u);
  } else if (v.is_number_integer()) {
    x = v.get<long long>();
  } else {
    throw Malformed{where + key, want};
  }
  if (x < lo || x > hi) throw Malformed{where + key, want};
  return int(x);
}

double finiteAt(const json& obj, const char* key, const std::string& where, double lo) {
  const std::string want = "a finite number of at least " + std::to_string(lo);
  const json& v = member(obj, key, where, want);
  if (!v.is_number()) throw Malformed{where + key, want};
  const double x = v.get<double>();
  if (!std::isfinite(x) || x < lo) throw Malformed{where + key, want};
  return x;
}

bool boolAt(const json& obj, const char* key, const std::string& where, bool fallback) {
  if (!obj.is_object() || !obj.contains(key)) return fallback;
  if (!obj[key].is_boolean()) throw Malformed{where + key, "true or false"};
  return obj[key].get<bool>();
}

bool hex16(const std::string& h) {
  return h.size() == 16 &&
         std::all_of(h.begin(), h.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
}

RenderOptions renderOptions(const json& j) {
  const std::string w = "render.";
  RenderOptions o;
  o.mode = stringAt(j, "mode", w);
  if (o.mode != "" && o.mode != "liquid" && o.mode != "particles")
    throw Malformed{w + "mode", "\"\", \"liquid\" or \"particles\""};
  if (!parseColorField(stringAt(j, "color_by", w), o.colorBy))
    throw Malformed{w + "color_by", "\"speed\", \"pressure\", \"density\", \"age\", \"color\" or \"material\""};
  const json& range = member(j, "range", w, "null or two finite numbers");
  if (!range.is_null()) {
    if (!range.is_array() || range.size() != 2 || !range[0].is_number() || !range[1].is_number() ||
        !std::isfinite(range[0].get<double>()) || !std::isfinite(range[1].get<double>()))
      throw Malformed{w + "range", "null or two finite numbers"};
    o.range = std::array<double, 2>{range[0].get<double>(), range[1].get<double>()};
  }
  if (!member(j, "overlay", w, "true or false").is_boolean()) throw Malformed{w + "overlay", "true or false"};
  o.overlay = j["overlay"].get<bool>();
  if (j.contains("outline")) {  // manifests written before the outline existed have none
    if (!j["outline"].is_boolean()) throw Malformed{w + "outline", "true or false"};
    o.outline = j["outline"].get<bool>();
  }
  o.foamSpeed = finiteAt(j, "foam_speed", w, 0);
  o.depthScale = finiteAt(j, "depth_scale", w, 0);
  // Manifests written before the CPU's splat existed have none: their frames came from the GL's
  // point sprites.
  o.splat = SplatPath::Gl;
  if (j.contains("splat")) {
    const json& v = j["splat"];
    if (!v.is_string() || !parseSplatPath(v.get<std::string>(), o.splat))
      throw Malformed{w + "splat", "\"auto\", \"cpu\" or \"gl\""};
  }
  return o;
}

}  // namespace

std::string frameFileName(std::int64_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", int(frame));
  return name;
}

RenderOptions renderOptionsFromJson(const json& j) {
  try {
    return renderOptions(j);
  } catch (const Malformed& m) {
    throw UsageError("the manifest's render options are malformed: '" + m.key + "' is missing or not " + m.want +
                     " (as sph2d run writes it)");
  }
}

std::vector<ManifestEnv> manifestEnvironment(const json& m) {
  std::vector<ManifestEnv> out;
  if (!m.is_object() || !m.contains("environment") || !m["environment"].is_array()) return out;
  const std::vector<std::string> known = recordedEnvironmentNames();
  auto printable = [](const std::string& t) {
    std::string r;
    for (char ch : t.substr(0, 40)) r += (ch >= 0x20 && ch < 0x7f) ? ch : '?';
    return r + (t.size() > 40 ? "..." : "");
  };
  for (const json& e : m["environment"]) {
    ManifestEnv me;
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() ||
        (e.contains("value") && !e["value"].is_string())) {
      me.name = "(malformed)";
      me.problem = "an entry is an object with a string name and value";
      out.push_back(me);
      continue;
    }
    me.name = e["name"].get<std::string>();
    me.value = e.contains("value") ? e["value"].get<std::string>() : std::string();
    const bool recorded = std::find(known.begin(), known.end(), me.name) != known.end();
    const bool plain = me.value.size() <= 64 && std::all_of(me.value.begin(), me.value.end(), [](char ch) {
                         return std::isalnum(static_cast<unsigned char>(ch)) || std::strchr("_.,:=+-", ch) != nullptr;
                       });
    if (!recorded) {
      std::string names;
      for (const std::string& k : known) names += (names.empty() ? "" : ", ") + k;
      me.problem = "sph2d records only its renderer's settings (" + names + ")";
      me.name = printable(me.name);
    } else if (!plain) {
      me.problem = "its value is not a plain setting (at most 64 of A-Z a-z 0-9 _ . , : = + -)";
    }
    out.push_back(me);
  }
  return out;
}

ManifestView parseManifest(const std::string& text, const std::string& path) {
  ManifestView v;
  json& m = v.json;
  try {
    m = json::parse(text);
  } catch (const json::exception& e) {
    throw UsageError(path + " is not valid JSON: " + e.what());
  }
  try {
    if (!m.is_object() || !m.contains("format") || m["format"] != "sph2d-frames")
      throw UsageError(path + " is not an sph2d frames manifest (its \"format\" is not \"sph2d-frames\")");
    const json& run = member(m, "run", "", "an object");
    v.frames = intAt(run, "frames", "run.", 0, 100000000);
    v.every = intAt(run, "every", "run.", 1, 100000000);
    const bool realtime = boolAt(run, "realtime", "run.", false);
    v.renderer = stringAt(m, "renderer", "");
    if (m.contains("cpu")) v.cpu = stringAt(m, "cpu", "");
    v.sceneHash = stringAt(member(m, "scene", "", "an object"), "xxh64", "scene.");
    v.render = renderOptions(member(m, "render", "", "the render options sph2d run writes"));
    const bool complete = boolAt(m, "complete", "", false);
    int written = -1;  // stop.frames_written, when the manifest says
    if (m.contains("stop") && !m["stop"].is_null()) {
      const json& st = m["stop"];
      if (!st.is_object())
        throw Malformed{"stop", "null or an object with reason and message strings and frames_written"};
      (void)stringAt(st, "reason", "stop.");
      if (st.contains("message")) (void)stringAt(st, "message", "stop.");
      if (st.contains("frames_written")) written = intAt(st, "frames_written", "stop.", 0, 100000000);
    }
    if (m.contains("events") && !m["events"].is_array()) throw Malformed{"events", "an array"};
    if (m.contains("environment") && !m["environment"].is_array()) throw Malformed{"environment", "an array"};
    const json& list = member(m, "frames", "", "an array of objects with frame, file, rgba_xxh64 and state_hash");
    if (!list.is_array()) throw Malformed{"frames", "an array of objects with frame, file, rgba_xxh64 and state_hash"};
    int last = -1;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const json& f = list[k];
      const std::string at = "frames[" + std::to_string(k) + "].";
      if (!f.is_object())
        throw Malformed{"frames[" + std::to_string(k) + "]", "an object with frame, file, rgba_xxh64 and state_hash"};
      const int frame = intAt(f, "frame", at, 0, 100000000);
      if (frame >= v.frames || frame % v.every != 0 || frame <= last)
        throw UsageError(path + ": frames[" + std::to_string(k) + "]: frame " + std::to_string(frame) +
                         " is not a kept frame of the run after frame " + std::to_string(last) + " (frames 0.." +
                         std::to_string(v.frames - 1) + ", every " + std::to_string(v.every) + ", in order)");
      if (stringAt(f, "file", at) != frameFileName(frame))
        throw UsageError(path + ": frames[" + std::to_string(k) + "]: its file must be " + frameFileName(frame) +
                         " (a manifest names only its own frames)");
      if (!hex16(stringAt(f, "rgba_xxh64", at)) || !hex16(stringAt(f, "state_hash", at)))
        throw UsageError(path + ": frames[" + std::to_string(k) + "]: rgba_xxh64 and state_hash must be 16 hex digits");
      v.expected[frame] = f;
      last = frame;
    }
    // The list against the run: complete → every kept frame 0, every, 2·every, … (a
    // real-time run may have dropped some); stopped → the first frames_written of them.
    // The kept frames are counted, not listed: run.frames sizes no allocation.
    const std::size_t keptCount = std::size_t(v.frames + v.every - 1) / std::size_t(v.every);
    std::size_t prefix = keptCount;
    if (!complete) {
      prefix = std::min(keptCount, written >= 0 ? std::size_t(written) : v.expected.size());
      if (!realtime && v.expected.size() != prefix)
        v.listProblems.push_back("the run stopped after writing " + std::to_string(prefix) +
                                 " frames, but the manifest lists " + std::to_string(v.expected.size()));
    }
    if (!realtime) {
      // Listed frames are kept frames in increasing order, so the first k kept frames are
      // all listed exactly when the k-th listed frame (if any) is kept frame k − 1.
      std::size_t k = 0;
      for (const auto& [frame, entry] : v.expected) {
        if (k == prefix || std::size_t(frame) != k * std::size_t(v.every)) break;
        ++k;
      }
      if (k < prefix)
        v.listProblems.push_back(std::string(complete ? "the manifest says the run is complete, but " : "") +
                                 "it lists " + std::to_string(v.expected.size()) + " of the run's " +
                                 std::to_string(prefix) + " kept frames (the first missing: frame " +
                                 std::to_string(k * std::size_t(v.every)) + ")");
    }
  } catch (const Malformed& bad) {
    throw UsageError(path + ": the key '" + bad.key + "' is missing or not " + bad.want + " (as sph2d run writes it)");
  } catch (const json::exception& e) {  // not expected: every read above checks its type first
    throw UsageError(path + ": malformed (" + e.what() + ")");
  }
  return v;
}

ManifestView readManifest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read the manifest " + path);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) throw UsageError("cannot read the manifest " + path);
  return parseManifest(text.str(), path);
}

}  // namespace sph2d::cli
