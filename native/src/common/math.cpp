// Out-of-line pieces of the geometry vocabulary (math.h).
#include "common/math.h"

namespace drape {

// Eigen's FromTwoVectors handles two nearly opposite vectors with a 2x3 JacobiSVD, and a file that
// calls it instantiates the SVD with its QR and matrix-product kernels: about 22 s of compiling
// per file under ASan + UBSan and 11 s in release (tracker, proxy_builder and body_model before
// and after; docs/robustness.md "CI time"). Defined here once, it is compiled once; the result is
// Eigen's, to the bit.
Quat rotationBetween(const Vec3& from, const Vec3& to) { return Quat::FromTwoVectors(from, to); }

}  // namespace drape
