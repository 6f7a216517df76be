// Body volume against real people: every ANSUR II subject in the shared half (993 women), built
// from their own measured height, weight and eight girths, in the rest pose. A body's density is
// close to 1 010 kg/m^3, so the enclosed volume should be within 10 % of weight / 1 010.
#include "body/body_model.h"
#include "body/girth_regression.h"
#include "body/mesh_metrics.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace drape {
namespace {

TEST(BodyVolumeAnsur, WithinTenPercentOfWeightOverDensity) {
  DRAPE_REQUIRE_SHARED(path, "anthropometry_ansur2/ANSUR_II_FEMALE_Public_shared_half.csv");
  std::vector<AnsurSubject> subjects;
  std::string err;
  ASSERT_TRUE(loadAnsurCsv(path, subjects, err)) << err;
  ASSERT_GT(subjects.size(), 900u);

  BodyModel body(resolveShape(BodyShapeInput{}), BodyModelParams{});
  std::vector<double> relErrors;
  int within = 0, used = 0;
  for (const AnsurSubject& s : subjects) {
    BodyShapeInput in;
    in.height_m = s.height_m;
    in.weight_kg = s.weight_kg;
    bool complete = true;
    for (int g = 0; g < kGirthCount; ++g) {
      if (!std::isfinite(s.mm[g])) complete = false;
      in.girth_mm[g] = std::isfinite(s.mm[g]) ? s.mm[g] : 0.0f;
    }
    if (!complete) continue;
    const ResolvedShape shape = resolveShape(in);
    body.setShape(shape);
    body.update(restPose(shape));
    const double litres = 1000.0 * signedVolume(body.positions(), body.indices());
    const double expected = 1000.0 * s.weight_kg / 1010.0;
    const double rel = (litres - expected) / expected;
    relErrors.push_back(rel);
    if (std::fabs(rel) <= 0.10) ++within;
    ++used;
  }
  ASSERT_GT(used, 900);
  std::sort(relErrors.begin(), relErrors.end());
  const double median = relErrors[relErrors.size() / 2];
  const double p05 = relErrors[relErrors.size() * 5 / 100], p95 = relErrors[relErrors.size() * 95 / 100];
  RecordProperty("median_rel_error", std::to_string(median));
  std::printf("ANSUR II volume check: %d subjects, median %+.1f %%, P5 %+.1f %%, P95 %+.1f %%, within 10 %%: %.1f %%\n",
              used, 100 * median, 100 * p05, 100 * p95, 100.0 * within / used);
  EXPECT_LT(std::fabs(median), 0.05) << "systematic volume bias";
  EXPECT_GE(static_cast<double>(within) / used, 0.90) << "fewer than 90 % of real bodies within 10 %";
}

}  // namespace
}  // namespace drape
