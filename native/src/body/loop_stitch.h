// Triangulating between two rows of vertices: the one tool the body mesh and the garment
// templates both build their tubes and branch points with.
//
// Winding: for two rows L -> U along a tube (points advancing from the frame's x towards its z
// axis) the triangles (L_j, U_j, L_j+1) and (L_j+1, U_j, U_j+1) face outwards.
#pragma once

#include "common/math.h"

#include <cstdint>
#include <vector>

namespace drape {

using Loop = std::vector<uint32_t>;

// Quads between two rows of n vertices, closed (rings) or open (strips).
void stitchEqual(const uint32_t* L, const uint32_t* U, int n, bool closed, std::vector<uint32_t>& out);

// Closed loops of different sizes: advance along whichever loop is behind in normalised
// parameter ("zipper"). U is first rotated so that its start lies nearest L's start, measured on
// `positions`, which keeps the stitch from twisting. `rotation` (optional): when it points at a
// value >= 0 that rotation of U is used as given; otherwise the chosen one is written there (a
// garment cut again for another body replays its first cut's choices: garment_templates.h).
void stitchLoops(const Loop& L, Loop U, const std::vector<Vec3>& positions, std::vector<uint32_t>& out,
                 int* rotation = nullptr);

}  // namespace drape
