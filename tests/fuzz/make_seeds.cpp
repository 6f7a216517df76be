// Writes the fuzzers' seed corpora from small slices of the shared data (nothing is copied into
// the repository): run by the build (tests/fuzz/CMakeLists.txt) and by tests/fuzz/run.sh.
//   drape-fuzz-seeds <shared data dir> <output dir>
// Output: <out>/recording (Kinect CSV: the first 20 frames of each take, also cut to 20 and 32
// joints; BVH: the hierarchy and the first 10 frames; .drec written by drape_recording_save from
// those slices), <out>/obj (one MakeHuman garment whole, a 300-face slice of it, a hand-made
// strip), <out>/capi (C ABI programs for fuzz_capi.cpp driven by the first 20 frames of a real
// Kinect take, with and without NaN / teleport / jitter / lost-joint perturbations).
// Missing shared files are skipped (the hand-made seeds are always written).
#include "drape/drape.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

bool readText(const fs::path& p, std::string& out) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return false;
  std::ostringstream s;
  s << f.rdbuf();
  out = s.str();
  return true;
}

void write(const fs::path& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary);
  f << bytes;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream s(text);
  std::string l;
  while (std::getline(s, l)) out.push_back(l);
  return out;
}

// Saves a recording parsed from `text` as .drec (through the C ABI, as a user would).
void saveDrec(const std::string& text, const fs::path& out) {
  drape_recording* r = nullptr;
  if (drape_recording_open_memory(text.data(), text.size(), DRAPE_LAYOUT_AUTO, &r) != DRAPE_OK) {
    std::fprintf(stderr, "drape-fuzz-seeds: %s\n", drape_last_error());
    return;
  }
  drape_recording_save(r, out.string().c_str());
  drape_recording_destroy(r);
}

// Kinect CSV line with only the first `joints` joints (the other layouts' field counts).
std::string cutCsvLine(const std::string& line, int joints) {
  std::vector<std::string> f;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      f.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  if (!cur.empty()) f.push_back(cur);
  std::string out = f[0];
  for (int j = 0; j < joints; ++j)
    for (int k = 0; k < 4; ++k) {
      const size_t i = 1 + 4 * static_cast<size_t>(j % 25) + k;
      out += "," + (i < f.size() ? f[i] : std::string("0"));
    }
  return out + "\n";
}

void recordingSeeds(const fs::path& data, const fs::path& out) {
  for (const char* take : {"Ges01_wavehand", "Ges02_balancinghands", "Ges04_comehere", "KinectReader_joints_closerange"}) {
    std::string text;
    if (!readText(data / "kinect_v2_msft_labanotation" / (std::string(take) + ".csv"), text)) continue;
    const std::vector<std::string> l = lines(text);
    std::string slice, k1, azure;
    for (size_t i = 0; i < l.size() && i < 20; ++i) {
      slice += l[i] + "\n";
      if (i < 5) {
        k1 += cutCsvLine(l[i], 20);
        azure += cutCsvLine(l[i], 32);
      }
    }
    write(out / (std::string("csv_") + take + ".csv"), slice);
    saveDrec(slice, out / (std::string("drec_") + take + ".drec"));
    if (std::string(take) == "Ges01_wavehand") {
      write(out / "csv_kinect1_20_joints.csv", k1);
      write(out / "csv_azure_32_joints.csv", azure);
      saveDrec(k1, out / "drec_kinect1.drec");
      saveDrec(azure, out / "drec_azure.drec");
    }
  }
  for (const char* take : {"131_01", "scaled_131_03"}) {
    std::string text;
    if (!readText(data / "cmu_mocap_bvh" / (std::string(take) + ".bvh"), text)) continue;
    const std::vector<std::string> l = lines(text);
    std::string slice;
    size_t i = 0;
    for (; i < l.size() && l[i].rfind("MOTION", 0) != 0; ++i) slice += l[i] + "\n";
    if (i + 2 >= l.size()) continue;
    slice += "MOTION\nFrames: 10\n" + l[i + 2] + "\n";
    for (size_t k = i + 3; k < l.size() && k < i + 13; ++k) slice += l[k] + "\n";
    write(out / (std::string("bvh_") + take + "_10_frames.bvh"), slice);
    saveDrec(slice, out / (std::string("drec_bvh_") + take + ".drec"));
  }
  // Hand-made: the smallest Kinect CSV.
  std::string one = "0";
  for (int j = 0; j < 25; ++j) one += ",0.1,0.2,2.5,2";
  write(out / "tiny.csv", one + "\n");
}

void objSeeds(const fs::path& data, const fs::path& out) {
  std::string text;
  if (readText(data / "garments_makehuman_cc0" / "female_elegantsuit01.obj", text)) {
    write(out / "female_elegantsuit01.obj", text);
    // The first 300 faces and the vertices they use, renumbered.
    std::vector<std::string> v;
    std::vector<std::vector<int>> faces;
    for (const std::string& l : lines(text)) {
      if (l.rfind("v ", 0) == 0) v.push_back(l);
      if (l.rfind("f ", 0) == 0 && faces.size() < 300) {
        std::istringstream s(l.substr(2));
        std::vector<int> f;
        std::string tok;
        while (s >> tok) f.push_back(std::stoi(tok.substr(0, tok.find('/'))));
        faces.push_back(f);
      }
    }
    std::map<int, int> renumber;
    std::string verts, fs_;
    for (const auto& f : faces) {
      fs_ += "f";
      for (int i : f) {
        auto it = renumber.find(i);
        if (it == renumber.end()) {
          it = renumber.emplace(i, static_cast<int>(renumber.size()) + 1).first;
          verts += v.at(static_cast<size_t>(i - 1)) + "\n";
        }
        fs_ += " " + std::to_string(it->second);
      }
      fs_ += "\n";
    }
    write(out / "female_elegantsuit01_300_faces.obj", "# slice\n" + verts + fs_);
  }
  // A hand-made tube around the chest (decimetres, MakeHuman frame): 12 x 3 vertices, quads.
  std::ostringstream t;
  for (int r = 0; r < 3; ++r)
    for (int i = 0; i < 12; ++i) {
      const double a = 6.283185307 * i / 12.0;
      t << "v " << 1.6 * std::cos(a) << " " << 4.5 - 0.8 * r << " " << 0.05 + 1.2 * std::sin(a) << "\n";
    }
  for (int r = 0; r < 2; ++r)
    for (int i = 0; i < 12; ++i) {
      const int a = r * 12 + i + 1, b = r * 12 + (i + 1) % 12 + 1;
      t << "f " << a << " " << b << " " << b + 12 << " " << a + 12 << "\n";
    }
  write(out / "tube.obj", t.str());
}

// ---- C ABI programs (byte layout of fuzz_capi.cpp's Machine) --------------------------------
struct Program {
  std::string b;
  void u8(int v) { b.push_back(static_cast<char>(v & 0xff)); }
  void f32(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    for (int i = 0; i < 4; ++i) u8(static_cast<int>((u >> (8 * i)) & 0xff));
  }
  void create(int slot) { u8(0), u8(slot), u8(0); }  // default desc
  void destroyContext(int slot) { u8(1), u8(slot); }
  // Real joints (raw push): Kinect v2, 1/30 s later.
  void pushRaw(int ctx, const drape_joint* j) {
    u8(4), u8(ctx), u8(1), u8(200);
    for (int i = 0; i < 25; ++i) {
      f32(j[i].position.x), f32(j[i].position.y), f32(j[i].position.z);
      u8(j[i].tracking_state);
    }
    u8(0);
  }
  // Synthetic pose with one perturbation (what: 0 x nasty, 2 teleport, 3 state, 4 zero bone, 5 jitter).
  void pushPose(int ctx, int what, int joint, int arg) {
    u8(2), u8(ctx), u8(1), u8(200), u8(1), u8(what), u8(joint), u8(arg), u8(0);
  }
  void step(int ctx, int k = 0) { u8(6), u8(ctx), u8(k); }
  void addTShirt(int ctx, int kind = 0) {
    u8(9), u8(ctx), u8(kind), u8(100), u8(0);  // 300 particles, default ease
    u8(120), u8(0);                            // dress 0.1 s, default desc
    u8(0);                                     // default cloth
  }
  void readGarment(int g) { u8(12), u8(g), u8(0), u8(0), u8(7); }
  void readBody(int ctx) { u8(13), u8(ctx), u8(0), u8(0), u8(15), u8(0), u8(0); }
  void destroyGarment(int g) { u8(14), u8(g); }
};

void capiSeeds(const fs::path& data, const fs::path& out) {
  std::vector<drape_joint> frames;  // 20 frames x 25 joints of a real take, or the synthetic pose
  std::string text;
  if (readText(data / "kinect_v2_msft_labanotation" / "Ges01_wavehand.csv", text)) {
    std::string slice;
    const std::vector<std::string> l = lines(text);
    for (size_t i = 0; i < l.size() && i < 20; ++i) slice += l[i] + "\n";
    drape_recording* r = nullptr;
    if (drape_recording_open_memory(slice.data(), slice.size(), DRAPE_LAYOUT_KINECT2, &r) == DRAPE_OK) {
      drape_recording_info info;
      info.struct_size = sizeof info;
      drape_recording_get_info(r, &info);
      frames.resize(25u * info.frame_count);
      for (uint32_t i = 0; i < info.frame_count; ++i) drape_recording_read_frame(r, i, &frames[25u * i], 25, nullptr);
      drape_recording_destroy(r);
    }
  }
  const size_t n = frames.size() / 25;
  {  // A real take, a T-shirt, every read.
    Program p;
    p.create(0);
    p.addTShirt(0);
    for (size_t i = 0; i < n; ++i) {
      p.pushRaw(0, &frames[25 * i]);
      p.step(0);
    }
    p.readGarment(0);
    p.readBody(0);
    p.destroyGarment(0);
    p.destroyContext(0);
    write(out / "real_take_tshirt.bin", p.b);
  }
  {  // Perturbations on the synthetic pose: NaN, Inf, 1e30, teleport, lost joints, zero bones.
    Program p;
    p.create(0);
    p.addTShirt(0, 2);  // skirt
    for (int i = 0; i < 4; ++i) p.pushPose(0, 5, 0, 200), p.step(0);
    p.pushPose(0, 0, 6, 12);   // NaN
    p.pushPose(0, 0, 6, 13);   // Inf
    p.pushPose(0, 0, 6, 4);    // 1e30
    p.pushPose(0, 2, 0, 239), p.step(0);  // teleport 2 m
    p.pushPose(0, 3, 5, 0), p.step(0, 2);  // elbow not tracked, 1/10 s
    p.pushPose(0, 4, 5, 0), p.step(0, 1);  // zero-length bone, 1/240 s
    p.readGarment(0);
    p.readBody(0);
    write(out / "perturbed_skirt.bin", p.b);
  }
  {  // Two contexts, garments destroyed with their context.
    Program p;
    p.create(0), p.create(1);
    p.addTShirt(0, 4), p.addTShirt(1, 1);
    for (int i = 0; i < 3; ++i) p.pushPose(0, 5, 0, 100), p.pushPose(1, 5, 0, 100), p.step(0), p.step(1);
    p.destroyContext(0);
    p.readGarment(0);
    p.readGarment(1);
    p.u8(15), p.u8(250);  // a stale context
    write(out / "two_contexts.bin", p.b);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: drape-fuzz-seeds <shared data dir> <output dir>\n");
    return 2;
  }
  const fs::path data = argv[1], out = argv[2];
  for (const char* d : {"recording", "obj", "capi"}) fs::create_directories(out / d);
  if (!fs::exists(data)) std::fprintf(stderr, "drape-fuzz-seeds: %s not found: hand-made seeds only\n", argv[1]);
  recordingSeeds(data, out / "recording");
  objSeeds(data, out / "obj");
  capiSeeds(data, out / "capi");
  return 0;
}
