// summary.md: the machine, the command, one table per sweep, the paper's Table 1 beside ours, the
// Bullet peer side by side with ratios, and where Drape stands against NvCloth (ANCHORS figures).
#pragma once

#include "bullet_peer.h"
#include "results.h"
#include "sweeps.h"

#include <string>
#include <vector>

namespace bench {

struct ReportInput {
  std::string command;
  std::vector<Take> takes;
  std::vector<Sweep> sweeps;
  std::vector<std::vector<Row>> rows;  // per sweep, same order
  std::vector<Row> table1;             // the default setting at ~2 000 particles, per take
  std::vector<Row> references;         // the converged references' own error figures (not timed)
  std::vector<PeerResult> peers;       // on takes[0]
  std::vector<PeerResult> spread;      // --peer-spread: Bullet 4 x 10 from other starting shirts
  double peer_field_m = kBulletFieldM;  // the Bullet field the target is judged on
  std::string peer_note;               // why there is no peer, if none
  std::vector<std::string> notes;      // plots not drawn etc.
  double energy_seconds = 0;
};

std::string machineDescription();
std::string renderReport(const ReportInput& in);

}  // namespace bench
