// Compiled when CMake did not find Bullet (Debian: libbullet-dev): drape-bench then says so and
// runs everything else.
#include "bullet_peer.h"

namespace bench {

bool bulletAvailable() { return false; }

bool runBulletPeer(const Take&, uint32_t, int, int, double, const PeerDriver&, PeerResult&, std::string& error,
                   uint32_t) {
  error =
      "this drape-bench was built without Bullet (install libbullet-dev, e.g. bash .ci/install-deps.sh, and "
      "rebuild) so the peer comparison was skipped";
  return false;
}

}  // namespace bench
