// Procedural garment templates sized to the body's shape: every garment is built from rings that
// follow the body's own feature rings (body/body_model.h), each the body ring's ellipse grown by
// an ease (clearance) in the same frame, so one template fits a thin and a heavy body alike.
// Construction, resolution and attachments: docs/cloth-solver.md, "Garment templates".
//
// Never throws, never asserts: bad input returns false with a message and leaves `out` untouched.
#pragma once

#include "body/body_model.h"
#include "common/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace drape {

enum class GarmentKind : int { TShirt = 0, LongSleeve = 1, Skirt = 2, Dress = 3, Trousers = 4 };

struct GarmentTemplateParams {
  GarmentKind kind = GarmentKind::TShirt;
  int target_particles = 2000;  // [200, 200000]; the result is within -5 / +2.5 % from 1 000 up
                                // (a ring of points is a larger step below that: within 10 %)
  float ease_m = 0.025f;        // clearance over the body, [0.002, 0.1] m (see docs/garments.md)
  float length_scale = 1.0f;    // scales hem / sleeve / leg lengths, [0.5, 1.5]
};

struct GarmentMesh {
  std::vector<Vec3> positions;     // rest/initial positions, metres, around the body's rest pose
  std::vector<uint32_t> indices;   // triangles, counter-clockwise seen from outside
  std::vector<uint32_t> pinned;    // attachment particles (waistband / collar + shoulder seam)
  std::vector<int> pin_ring;       // for each pinned particle: the body ring it follows
  std::vector<Vec3> pin_local;     // offset in that ring's frame: world = centre + frame * local
};

// The choices a template build makes from the body's proportions: the spacing, every ring and row
// count, the rotations of the stitched loops, which short edges were welded, and the attachments.
// Recorded on a garment's first build and replayed when it is cut again for another body (a shape
// change, the skeleton's calibration: GarmentSim::refitted), so the new cut has the same
// particles, triangles and attachments, placed as a template made for that body places them.
struct TemplateLayout {
  float h = 0.0f;
  std::vector<int> counts;          // in the order the build asks for them
  std::vector<int> rotations;       // stitchLoops rotations, in order
  std::vector<uint32_t> weld_root;  // per vertex before welding: the vertex it was merged into
  std::vector<uint32_t> pinned;     // after welding
  std::vector<int> pin_ring;
  bool empty() const { return counts.empty(); }
};

// body_in_rest_pose: a BodyModel updated with a rest pose (the tracking ellipsoids of that pose
// are what the template is pushed outside of). `record` (optional) receives the build's layout;
// `replay` (optional, from an earlier record of the same parameters) makes the same garment for
// this body: it fails ("does not fit the recorded layout") should the body be so unlike the first
// that the build goes another way.
bool makeGarmentTemplate(const BodyModel& body_in_rest_pose, const GarmentTemplateParams& p,
                         GarmentMesh& out, std::string& err, TemplateLayout* record = nullptr,
                         const TemplateLayout* replay = nullptr);

const char* garmentKindName(GarmentKind kind);
// Trousers and the long-sleeve top: their legs or sleeves reach the ankles or wrists, so they stay
// round the person's limbs only when cut to the person's limb lengths (DRAPE_GARMENT_CUT_BY_KIND).
inline bool garmentReachesLimbEnds(GarmentKind kind) {
  return kind == GarmentKind::Trousers || kind == GarmentKind::LongSleeve;
}

// pin_local from where the pinned particles are: each one's offset in its ring's frame on `body`
// (positions and pin_ring set; pin_local is resized).
void pinOffsetsFromPositions(const BodyModel& body, GarmentMesh& m);

}  // namespace drape
