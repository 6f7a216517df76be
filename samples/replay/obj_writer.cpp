#include "obj_writer.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace replay {

std::string objFileName(uint32_t frame_index) {
  char name[32];
  std::snprintf(name, sizeof name, "body_%05u.obj", frame_index);
  return name;
}

std::string garmentObjFileName(uint32_t frame_index) {
  char name[32];
  std::snprintf(name, sizeof name, "garment_%05u.obj", frame_index);
  return name;
}

std::string underObjFileName(uint32_t frame_index) {
  char name[32];
  std::snprintf(name, sizeof name, "under_%05u.obj", frame_index);
  return name;
}

bool writeObj(const std::string& path, const std::vector<drape_vec3>& positions,
              const std::vector<drape_vec3>& normals, const std::vector<uint32_t>& indices,
              const std::string& comment, std::string& error) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    error = "cannot create '" + path + "': " + std::strerror(errno);
    return false;
  }
  // Build the text in memory and write it once: a few hundred kB per frame at most.
  std::string text;
  text.reserve(positions.size() * 64 + indices.size() * 12 + 128);
  char line[128];
  text += "# " + comment + "\n";
  for (const drape_vec3& p : positions) {
    std::snprintf(line, sizeof line, "v %.6f %.6f %.6f\n", static_cast<double>(p.x),
                  static_cast<double>(p.y), static_cast<double>(p.z));
    text += line;
  }
  for (const drape_vec3& n : normals) {
    std::snprintf(line, sizeof line, "vn %.5f %.5f %.5f\n", static_cast<double>(n.x),
                  static_cast<double>(n.y), static_cast<double>(n.z));
    text += line;
  }
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const unsigned a = indices[t] + 1, b = indices[t + 1] + 1, c = indices[t + 2] + 1;
    std::snprintf(line, sizeof line, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
    text += line;
  }
  const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const bool closed = std::fclose(f) == 0;
  if (!wrote || !closed) {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace replay
