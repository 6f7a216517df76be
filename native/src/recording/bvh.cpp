// BVH motion capture (the CMU database as converted by cgspeed) mapped onto the Kinect v2 layout.
//
// Hierarchy: ROOT / JOINT / End Site blocks with OFFSET and CHANNELS, parsed without recursion
// (explicit stack, depth <= kBvhMaxDepth, <= kBvhMaxJoints joints). Each joint's CHANNELS order is
// honoured: the local rotation is the product of the rotation channels in declared order (Zrotation
// Yrotation Xrotation -> Rz*Ry*Rx) and a joint's world transform is
//   parent world * translate(offset + position channels) * rotation.
// Positions are converted to metres (unit detected from the rest-pose size) and to Kinect v2 camera
// space: x' = -x, y' = y, z' = 3 m - z (a 180 degree turn about +Y: the BVH subject faces +Z, a
// Kinect subject faces the sensor, -Z). See docs/recording-format.md for the joint mapping.
#include "recording/recording_internal.h"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace drape::recording_detail {

namespace {

// ---------------------------------------------------------------------------------------------
// Tokenizer with line numbers.
class Tokenizer {
 public:
  explicit Tokenizer(std::string_view text) : text_(text) {}

  // Next whitespace-separated token (empty at the end); line() is the line it starts on.
  std::string_view next() {
    skipSpace(true);
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
    return text_.substr(start, pos_ - start);
  }
  // The rest of the current line, trimmed; stops before the line break.
  std::string_view restOfLine() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') ++pos_;
    return trim(text_.substr(start, pos_ - start));
  }
  // Consumes one line break (if any) and returns the text after it.
  std::string_view afterLineBreak() {
    if (pos_ < text_.size() && text_[pos_] == '\r') ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '\n') ++pos_;
    ++line_;
    return text_.substr(pos_);
  }
  int line() const { return line_; }

 private:
  void skipSpace(bool crossLines) {
    while (pos_ < text_.size() && isSpace(text_[pos_])) {
      const char c = text_[pos_];
      if (c == '\n' || c == '\r') {
        if (!crossLines) return;
        if (c == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
        ++line_;
      }
      ++pos_;
    }
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

enum Channel : uint8_t { Xpos, Ypos, Zpos, Xrot, Yrot, Zrot };

bool channelFromName(std::string_view s, Channel& c) {
  static const char* const kNames[6] = {"Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"};
  for (int i = 0; i < 6; ++i) {
    if (equalsIgnoreCase(s, kNames[i])) {
      c = static_cast<Channel>(i);
      return true;
    }
  }
  return false;
}

struct Node {
  std::string name;  // "" for an End Site
  int parent = -1;
  bool endSite = false;
  bool hasOffset = false, hasChannels = false;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  int firstChannel = 0;
  int channelCount = 0;
  std::array<Channel, 6> channels{};
};

std::string nodeLabel(const std::vector<Node>& nodes, int i) {
  const Node& n = nodes[static_cast<std::size_t>(i)];
  if (!n.endSite) return "joint " + quoted(n.name);
  return "the End Site of joint " + quoted(nodes[static_cast<std::size_t>(n.parent)].name);
}

struct Hierarchy {
  std::vector<Node> nodes;  // pre-order: a parent always precedes its children
  int channelCount = 0;
  int jointCount = 0;
};

// A joint or End Site name: the rest of the line, with a trailing '{' (same-line brace) split off.
std::string_view readName(Tokenizer& tok, bool& braceOnLine) {
  std::string_view name = tok.restOfLine();
  braceOnLine = false;
  if (!name.empty() && name.back() == '{') {
    braceOnLine = true;
    name = trim(name.substr(0, name.size() - 1));
  }
  return name;
}

bool parseHierarchy(Tokenizer& tok, Hierarchy& h, std::string& err) {
  if (tok.next() != "HIERARCHY") {
    err = lineMsg(tok.line(), "expected HIERARCHY");
    return false;
  }
  std::string_view t = tok.next();
  if (t != "ROOT") {
    err = lineMsg(tok.line(), t.empty() ? "file ends after HIERARCHY (no ROOT)" : "expected ROOT, found " + quoted(t));
    return false;
  }
  std::vector<int> stack;
  int endSites = 0;

  // Opens a new node block: name already read; expects '{' unless it was on the name's line.
  auto open = [&](std::string_view name, bool endSite, bool braceOnLine) -> bool {
    const int line = tok.line();
    if (!endSite && name.empty()) {
      err = lineMsg(line, "joint without a name");
      return false;
    }
    if (!endSite && h.jointCount >= kBvhMaxJoints) {
      err = lineMsg(line, "more than " + std::to_string(kBvhMaxJoints) + " joints");
      return false;
    }
    if (endSite && endSites >= kBvhMaxJoints) {
      err = lineMsg(line, "more than " + std::to_string(kBvhMaxJoints) + " End Sites");
      return false;
    }
    if (static_cast<int>(stack.size()) >= kBvhMaxDepth) {
      err = lineMsg(line, "hierarchy nested deeper than " + std::to_string(kBvhMaxDepth) + " levels");
      return false;
    }
    if (!braceOnLine) {
      const std::string_view b = tok.next();
      if (b != "{") {
        err = lineMsg(tok.line(), "expected '{' after " + std::string(endSite ? "End Site" : "joint " + quoted(name)) +
                                      (b.empty() ? ", found the end of the file" : ", found " + quoted(b)));
        return false;
      }
    }
    Node n;
    n.name = std::string(name);
    n.endSite = endSite;
    n.parent = stack.empty() ? -1 : stack.back();
    h.nodes.push_back(std::move(n));
    stack.push_back(static_cast<int>(h.nodes.size()) - 1);
    if (endSite) ++endSites; else ++h.jointCount;
    return true;
  };

  auto endOfFile = [&](int node) {
    err = "unexpected end of file inside " + nodeLabel(h.nodes, node) + " (line " + std::to_string(tok.line()) +
          "; is the file truncated?)";
    return false;
  };

  bool brace = false;
  const std::string_view rootName = readName(tok, brace);
  if (!open(rootName, false, brace)) return false;

  while (!stack.empty()) {
    t = tok.next();
    const int line = tok.line();
    const int cur = stack.back();
    if (t.empty()) return endOfFile(cur);
    if (t == "OFFSET") {
      Node& n = h.nodes[static_cast<std::size_t>(cur)];
      if (n.hasOffset) {
        err = lineMsg(line, "second OFFSET in " + nodeLabel(h.nodes, cur));
        return false;
      }
      for (int a = 0; a < 3; ++a) {
        const std::string_view v = tok.next();
        if (v.empty()) return endOfFile(cur);
        if (!parseDouble(v, n.offset[a])) {
          err = lineMsg(tok.line(), "OFFSET of " + nodeLabel(h.nodes, cur) + ": " + quoted(v) + " is not a finite number");
          return false;
        }
      }
      n.hasOffset = true;
    } else if (t == "CHANNELS") {
      Node& n = h.nodes[static_cast<std::size_t>(cur)];
      if (n.endSite || n.hasChannels) {
        err = lineMsg(line, std::string(n.endSite ? "CHANNELS in " : "second CHANNELS in ") + nodeLabel(h.nodes, cur));
        return false;
      }
      const std::string_view countTok = tok.next();
      if (countTok.empty()) return endOfFile(cur);
      int count = -1;
      if (!parseInt(countTok, count) || count < 0 || count > 6) {
        err = lineMsg(tok.line(), "CHANNELS count " + quoted(countTok) + " is not 0..6");
        return false;
      }
      unsigned seen = 0;
      for (int c = 0; c < count; ++c) {
        const std::string_view name = tok.next();
        if (name.empty()) return endOfFile(cur);
        Channel ch{};
        if (!channelFromName(name, ch)) {
          err = lineMsg(tok.line(), "unknown channel " + quoted(name) + " in " + nodeLabel(h.nodes, cur) +
                                        " (expected X/Y/Z position/rotation)");
          return false;
        }
        if (seen & (1u << ch)) {
          err = lineMsg(tok.line(), "channel " + quoted(name) + " listed twice in " + nodeLabel(h.nodes, cur));
          return false;
        }
        seen |= 1u << ch;
        n.channels[static_cast<std::size_t>(c)] = ch;
      }
      n.channelCount = count;
      n.firstChannel = h.channelCount;
      n.hasChannels = true;
      h.channelCount += count;
    } else if (t == "JOINT") {
      if (h.nodes[static_cast<std::size_t>(cur)].endSite) {
        err = lineMsg(line, "JOINT inside an End Site");
        return false;
      }
      const std::string_view name = readName(tok, brace);
      if (!open(name, false, brace)) return false;
    } else if (t == "End") {
      if (h.nodes[static_cast<std::size_t>(cur)].endSite) {
        err = lineMsg(line, "End Site inside an End Site");
        return false;
      }
      const std::string_view rest = readName(tok, brace);
      if (!rest.empty() && rest != "Site") {
        err = lineMsg(line, "expected 'End Site', found 'End " + quoted(rest).substr(1));
        return false;
      }
      if (!open("", true, brace)) return false;
    } else if (t == "}") {
      const Node& n = h.nodes[static_cast<std::size_t>(cur)];
      if (!n.hasOffset || (!n.endSite && !n.hasChannels)) {
        err = lineMsg(line, nodeLabel(h.nodes, cur) + " has no " + (n.hasOffset ? "CHANNELS" : "OFFSET"));
        return false;
      }
      stack.pop_back();
    } else {
      err = lineMsg(line, "unexpected " + quoted(t) + " in " + nodeLabel(h.nodes, cur));
      return false;
    }
  }
  if (h.channelCount == 0) {
    err = "the BVH hierarchy declares no channels";
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Units: the skeleton's rest pose (offsets only) is compared with a human size.

struct Unit {
  const char* name;
  double metres;
};
constexpr Unit kUnits[] = {
    {"metre", 1.0},
    {"cmu-unit", 0.0254 / 0.45},  // CMU / cgspeed: 1 unit = (1/0.45) inch = 5.644 cm
    {"inch", 0.0254},
    {"centimetre", 0.01},
    {"millimetre", 0.001},
};
// Largest axis extent of a rest pose (End Sites included), in metres, that the unit choice aims at:
// 1.37 m for the CMU subject 131 (arms down, head top to toe tips). Candidates are picked by the
// nearest log-ratio, so e.g. CMU units win for extents between ~6.3 and ~39 file units.
constexpr double kRestExtentMetres = 1.5;

bool detectUnit(const Hierarchy& h, Unit& unit, double& extent, std::string& err) {
  std::vector<Eigen::Vector3d> p(h.nodes.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(0), hi = Eigen::Vector3d::Constant(0);
  for (std::size_t i = 0; i < h.nodes.size(); ++i) {
    const Node& n = h.nodes[i];
    p[i] = (n.parent < 0 ? Eigen::Vector3d::Zero() : p[static_cast<std::size_t>(n.parent)]) + n.offset;
    if (n.parent < 0) p[i].setZero();  // the root offset only moves the whole figure
    lo = lo.cwiseMin(p[i]);
    hi = hi.cwiseMax(p[i]);
  }
  extent = (hi - lo).maxCoeff();
  if (!std::isfinite(extent) || !(extent > 0)) {
    err = "the BVH rest pose has no size (all offsets zero or not finite): cannot tell its unit";
    return false;
  }
  double best = 1e300;
  for (const Unit& u : kUnits) {
    const double d = std::fabs(std::log(extent * u.metres / kRestExtentMetres));
    if (d < best) {
      best = d;
      unit = u;
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Mapping onto the Kinect v2 layout (JointType order).

struct MapEntry {
  const char* joint;  // CMU/cgspeed joint name
  bool endSite;       // use the first End Site under that joint (see resolveMapping when it has none)
  const char* with;   // when set and present: the midpoint of `joint` and this joint
};
// Index = Kinect v2 JointType. The CMU spine is mapped so that SpineShoulder sits level with the
// shoulders, as a Kinect puts it (3.5 cm above them in the Labanotation captures): CMU's Chest2 is
// 8 cm below the shoulder joints, and mapped there the torso's top ring and every top's
// shoulders sat that far down the arms (docs/recording-format.md, "Joint mapping").
constexpr MapEntry kKinect2Map[25] = {
    {"Hips", false, nullptr},          // 0 SpineBase
    {"Chest", false, "Chest2"},        // 1 SpineMid (lowerback sits on the Hips: zero offset)
    {"Head", false, nullptr},          // 2 Neck (CMU Head: the top of the neck)
    {"Head", true, nullptr},           // 3 Head (the Head's End Site)
    {"LeftShoulder", false, nullptr},  // 4 ShoulderLeft
    {"LeftElbow", false, nullptr},     // 5 ElbowLeft
    {"LeftWrist", false, nullptr},     // 6 WristLeft
    {"LFingers", false, nullptr},      // 7 HandLeft (lhand sits on the wrist: zero offset)
    {"RightShoulder", false, nullptr}, // 8 ShoulderRight
    {"RightElbow", false, nullptr},    // 9 ElbowRight
    {"RightWrist", false, nullptr},    // 10 WristRight
    {"RFingers", false, nullptr},      // 11 HandRight
    {"LeftHip", false, nullptr},       // 12 HipLeft
    {"LeftKnee", false, nullptr},      // 13 KneeLeft
    {"LeftAnkle", false, nullptr},     // 14 AnkleLeft
    {"LeftToe", false, nullptr},       // 15 FootLeft
    {"RightHip", false, nullptr},      // 16 HipRight
    {"RightKnee", false, nullptr},     // 17 KneeRight
    {"RightAnkle", false, nullptr},    // 18 AnkleRight
    {"RightToe", false, nullptr},      // 19 FootRight
    {"Neck", false, nullptr},          // 20 SpineShoulder (CMU Neck: the base of the neck, level with the shoulders)
    {"LFingers", true, nullptr},       // 21 HandTipLeft (finger tips)
    {"LThumb", true, nullptr},         // 22 ThumbLeft (thumb tip)
    {"RFingers", true, nullptr},       // 23 HandTipRight
    {"RThumb", true, nullptr},         // 24 ThumbRight
};
constexpr int kSpineMid = 1, kSpineBase = 0, kSpineShoulder = 20, kHead = 3;

// Where each Kinect joint comes from: node a, or the midpoint of a and b (b >= 0); a = -1 for
// SpineMid means "midpoint of SpineBase and SpineShoulder"; extrapolated: the Head without an End
// Site, placed as far above the CMU Head as that is above the CMU Neck (not a zero-length bone).
struct Source {
  int a = -1, b = -1;
  bool extrapolated = false;
};

bool resolveMapping(const Hierarchy& h, std::array<Source, 25>& src, std::string& err) {
  auto find = [&](const char* name) {
    for (std::size_t i = 0; i < h.nodes.size(); ++i)
      if (!h.nodes[i].endSite && equalsIgnoreCase(h.nodes[i].name, name)) return static_cast<int>(i);
    return -1;
  };
  std::string missing;
  for (int k = 0; k < 25; ++k) {
    Source& out = src[static_cast<std::size_t>(k)];
    out = Source{};
    int i = find(kKinect2Map[k].joint);
    if (i >= 0 && kKinect2Map[k].endSite) {
      int tip = -1;
      for (std::size_t c = static_cast<std::size_t>(i) + 1; c < h.nodes.size() && tip < 0; ++c)
        if (h.nodes[c].parent == i && h.nodes[c].endSite) tip = static_cast<int>(c);
      if (tip >= 0) i = tip;
      else out.extrapolated = k == kHead;  // else the joint itself (a hand without its tip)
    }
    if (i < 0 && k != kSpineMid && missing.find(kKinect2Map[k].joint) == std::string::npos)
      missing += std::string(missing.empty() ? "" : ", ") + kKinect2Map[k].joint;
    out.a = i;
    if (i >= 0 && kKinect2Map[k].with != nullptr) out.b = find(kKinect2Map[k].with);
  }
  if (!missing.empty()) {
    err = "the BVH skeleton lacks joint(s) " + missing +
          " needed for the Kinect v2 mapping (CMU/cgspeed joint names expected, see docs/recording-format.md)";
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------

Eigen::Matrix3d axisRotation(Channel c, double degrees) {
  const double r = degrees * (3.14159265358979323846 / 180.0);
  const Eigen::Vector3d axis = c == Xrot ? Eigen::Vector3d::UnitX() : c == Yrot ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  return Eigen::AngleAxisd(r, axis).toRotationMatrix();
}

}  // namespace

bool parseBvh(std::string_view text, int layoutHint, Recording& out, std::string& err, BvhImportInfo* info) {
  out = Recording{};
  out.format = RecordingFormat::Bvh;
  out.layout = Layout::Kinect2;
  if (!checkLayoutHint(layoutHint, Layout::Kinect2, "a BVH file (always mapped onto the Kinect v2 layout)", err))
    return false;

  text = stripBom(text);
  Tokenizer tok(text);
  Hierarchy h;
  if (!parseHierarchy(tok, h, err)) return false;

  // MOTION / Frames: N / Frame Time: t
  std::string_view t = tok.next();
  if (t != "MOTION") {
    if (t.empty()) err = "MOTION section missing: the file ends after the hierarchy";
    else if (t == "ROOT") err = lineMsg(tok.line(), "a second ROOT: BVH files with several skeletons are not supported");
    else err = lineMsg(tok.line(), "expected MOTION after the hierarchy, found " + quoted(t));
    return false;
  }
  int declaredFrames = 0;
  t = tok.next();
  std::string_view v = tok.next();
  if (t != "Frames:" || !parseInt(v, declaredFrames) || declaredFrames < 1 || declaredFrames > kRecordingMaxFrames) {
    err = lineMsg(tok.line(), "expected 'Frames: N' with 1 <= N <= " + std::to_string(kRecordingMaxFrames) + " after MOTION");
    return false;
  }
  double frameTime = 0;
  const std::string_view t1 = tok.next(), t2 = tok.next();
  v = tok.next();
  if (t1 != "Frame" || t2 != "Time:" || !parseDouble(v, frameTime) || !(frameTime >= 1e-5) || frameTime > 10) {
    err = lineMsg(tok.line(), "expected 'Frame Time: seconds' (1e-5 .. 10 s) after the Frames line");
    return false;
  }
  if (!tok.restOfLine().empty()) {
    err = lineMsg(tok.line(), "unexpected text after the Frame Time value");
    return false;
  }

  Unit unit{};
  double extent = 0;
  std::array<Source, 25> src{};
  if (!detectUnit(h, unit, extent, err) || !resolveMapping(h, src, err)) return false;

  // Frame lines.
  const int firstMotionLine = tok.line() + 1;
  LineReader lines(tok.afterLineBreak(), firstMotionLine);
  std::string_view line;
  const auto nodeCount = h.nodes.size();
  const auto channelCount = static_cast<std::size_t>(h.channelCount);
  std::vector<double> ch(channelCount);
  std::vector<Eigen::Matrix3d> rot(nodeCount);
  std::vector<Eigen::Vector3d> pos(nodeCount);
  // Reserve no more than the remaining text could hold (>= 2 bytes per channel value).
  const std::size_t fit = text.size() / (2 * channelCount) + 1;
  out.frames.reserve(std::min<std::size_t>(static_cast<std::size_t>(declaredFrames), fit));

  while (lines.next(line)) {
    const int ln = lines.number();
    std::size_t p = 0;
    std::string_view first = nextToken(line, p);
    if (first.empty()) continue;  // blank lines (e.g. a trailing newline) are ignored
    if (static_cast<int>(out.frames.size()) >= declaredFrames) {
      err = lineMsg(ln, "more frame lines than the declared 'Frames: " + std::to_string(declaredFrames) + "'");
      return false;
    }
    const int frameIndex = static_cast<int>(out.frames.size());
    std::size_t n = 0;
    for (std::string_view tk = first; !tk.empty(); tk = nextToken(line, p)) {
      if (n >= channelCount) {
        err = lineMsg(ln, "frame " + std::to_string(frameIndex) + " has more than the " + std::to_string(channelCount) +
                              " values the hierarchy's CHANNELS declare");
        return false;
      }
      if (!parseDouble(tk, ch[n])) {
        err = lineMsg(ln, "frame " + std::to_string(frameIndex) + ", value " + std::to_string(n + 1) + ": " + quoted(tk) +
                              " is not a finite number");
        return false;
      }
      ++n;
    }
    if (n != channelCount) {
      err = lineMsg(ln, "frame " + std::to_string(frameIndex) + " has " + std::to_string(n) + " values, the hierarchy's CHANNELS declare " +
                            std::to_string(channelCount));
      return false;
    }

    // Forward kinematics (file units).
    for (std::size_t i = 0; i < nodeCount; ++i) {
      const Node& nd = h.nodes[i];
      Eigen::Vector3d trans = nd.offset;
      Eigen::Matrix3d local = Eigen::Matrix3d::Identity();
      for (int c = 0; c < nd.channelCount; ++c) {
        const Channel kind = nd.channels[static_cast<std::size_t>(c)];
        const double value = ch[static_cast<std::size_t>(nd.firstChannel + c)];
        if (kind <= Zpos) trans[kind] += value;
        else local = local * axisRotation(kind, value);
      }
      if (nd.parent < 0) {
        pos[i] = trans;
        rot[i] = local;
      } else {
        const auto pi = static_cast<std::size_t>(nd.parent);
        pos[i] = rot[pi] * trans + pos[pi];
        rot[i] = rot[pi] * local;
      }
    }

    RecordingFrame frame;
    frame.time_s = frameIndex * frameTime;
    frame.joints.resize(25);
    auto at = [&](int node) -> const Eigen::Vector3d& { return pos[static_cast<std::size_t>(node)]; };
    for (std::size_t k = 0; k < 25; ++k) {
      const Source& from = src[k];
      Eigen::Vector3d w;
      if (from.a < 0) w = 0.5 * (at(src[kSpineBase].a) + at(src[kSpineShoulder].a));
      else if (from.b >= 0) w = 0.5 * (at(from.a) + at(from.b));
      else if (from.extrapolated) w = 2.0 * at(from.a) - at(src[kSpineShoulder].a);
      else w = at(from.a);
      w *= unit.metres;
      const Eigen::Vector3d kinect(-w.x(), w.y(), kBvhSensorDistanceM - w.z());
      const Vec3 f = kinect.cast<float>();
      if (!isFinite(f)) {
        err = lineMsg(ln, "frame " + std::to_string(frameIndex) + " gives non-finite joint positions (values too large)");
        return false;
      }
      frame.joints[k].position = f;
      frame.joints[k].state = TrackingState::Tracked;
    }
    out.frames.push_back(std::move(frame));
  }
  if (static_cast<int>(out.frames.size()) != declaredFrames) {
    err = "truncated BVH: 'Frames: " + std::to_string(declaredFrames) + "' declared but only " +
          std::to_string(out.frames.size()) + " frame lines found (line " + std::to_string(lines.number()) + " is the last)";
    return false;
  }
  out.nominal_rate_hz = static_cast<float>(1.0 / frameTime);
  if (info) {
    info->metres_per_unit = unit.metres;
    info->unit_name = unit.name;
    info->rest_extent_units = extent;
    info->joint_count = h.jointCount;
    info->channel_count = h.channelCount;
    info->frame_time_s = frameTime;
  }
  return true;
}

}  // namespace drape::recording_detail
