#include "body/girth_regression.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace drape {
namespace {

constexpr const char* kAnsurFile = "anthropometry_ansur2/ANSUR_II_FEMALE_Public_shared_half.csv";

Measure measureAt(int i) { return static_cast<Measure>(i); }

std::string writeTempFile(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + "girth_regression_" + name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

// A synthetic ANSUR-shaped CSV where every measure follows an exact, known power law:
// measure i = (100 + 10 i) * (h / 1.63)^heightExponent(i) * (w / 66)^weightExponent(i).
double heightExponent(int i) { return 0.1 * (i % 5) - 0.1; }
double weightExponent(int i) { return 0.05 * (i % 7) + 0.1; }

struct SyntheticRow {
  std::string stature_mm, weight_tenths_kg;
  std::vector<std::string> measures_mm;
};

std::vector<SyntheticRow> syntheticRows() {
  std::vector<SyntheticRow> rows;
  for (int hi = 0; hi < 6; ++hi) {
    for (int wi = 0; wi < 6; ++wi) {
      const double h = 1.45 + 0.08 * hi, w = 45.0 + 13.0 * wi;
      SyntheticRow row{std::to_string(h * 1000.0), std::to_string(w * 10.0), {}};
      for (int i = 0; i < kMeasureCount; ++i) {
        const double mm = (100.0 + 10.0 * i) * std::pow(h / kReferenceHeightM, heightExponent(i)) *
                          std::pow(w / kReferenceWeightKg, weightExponent(i));
        row.measures_mm.push_back(std::to_string(mm));
      }
      rows.push_back(row);
    }
  }
  return rows;
}

// Columns: SubjectId, stature, the measures in enum order, weightkg, Gender (as in ANSUR, the
// needed columns are scattered among others).
std::string toCsv(const std::vector<SyntheticRow>& rows, const char* eol) {
  std::string csv = "SubjectId,stature";
  for (int i = 0; i < kMeasureCount; ++i) csv += std::string(",") + ansurColumn(measureAt(i));
  csv += std::string(",weightkg,Gender") + eol;
  int id = 10000;
  for (const SyntheticRow& row : rows) {
    csv += std::to_string(id++) + "," + row.stature_mm;
    for (const std::string& v : row.measures_mm) csv += "," + v;
    csv += "," + row.weight_tenths_kg + ",Female" + eol;
  }
  return csv;
}

// ---- Without the shared data ---------------------------------------------------------------

TEST(GirthRegression, MeasureNamesAreSnakeCaseAndUnique) {
  const char* const girths[kGirthCount] = {"neck", "chest", "waist", "hip", "thigh", "calf", "upper_arm", "forearm"};
  for (int i = 0; i < kGirthCount; ++i) EXPECT_STREQ(measureName(measureAt(i)), girths[i]);
  std::set<std::string> names;
  for (int i = 0; i < kMeasureCount; ++i) {
    const std::string name = measureName(measureAt(i));
    EXPECT_EQ(name.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string::npos) << name;
    EXPECT_TRUE(names.insert(name).second) << "duplicate " << name;
    EXPECT_STRNE(ansurColumn(measureAt(i)), "") << name;
  }
  EXPECT_STREQ(measureName(Measure::Count), "?");
  EXPECT_STREQ(ansurColumn(static_cast<Measure>(-1)), "");
}

TEST(GirthRegression, FitRecoversAKnownPowerLawFromACrlfFile) {
  const std::vector<SyntheticRow> rows = syntheticRows();
  const std::string path = writeTempFile("synthetic.csv", toCsv(rows, "\r\n"));
  std::vector<AnsurSubject> subjects;
  std::string err;
  ASSERT_TRUE(loadAnsurCsv(path, subjects, err)) << err;
  ASSERT_EQ(subjects.size(), rows.size());
  for (int i = 0; i < kMeasureCount; ++i) {
    const Measure m = measureAt(i);
    const RegressionCoefficients c = fitMeasure(subjects, m);
    EXPECT_EQ(c.subjects, static_cast<int>(rows.size())) << measureName(m);
    EXPECT_NEAR(std::exp(c.log_intercept), 100.0 + 10.0 * i, 1e-3) << measureName(m);
    EXPECT_NEAR(c.height_exponent, heightExponent(i), 1e-5) << measureName(m);
    EXPECT_NEAR(c.weight_exponent, weightExponent(i), 1e-5) << measureName(m);
    const FitReport report = evaluate(subjects, m, c);
    EXPECT_GT(report.r2, 0.999999) << measureName(m);
    EXPECT_LT(report.mae_mm, 1e-3) << measureName(m);
  }
}

TEST(GirthRegression, BadCellsSkipOnlyThatSubjectForThatMeasure) {
  std::vector<SyntheticRow> rows = syntheticRows();
  const int chest = static_cast<int>(Measure::Chest), waist = static_cast<int>(Measure::Waist);
  rows[1].measures_mm[chest] = "";       // empty cell
  rows[2].measures_mm[waist] = "12abc";  // trailing garbage
  rows[3].measures_mm[waist] = "-850";   // impossible value
  rows[4].measures_mm[chest] = "nan";    // parses, but not a measurement
  rows[5].stature_mm = "";               // no height: unusable for every measure
  const std::string path = writeTempFile("bad_cells.csv", toCsv(rows, "\n"));
  std::vector<AnsurSubject> subjects;
  std::string err;
  ASSERT_TRUE(loadAnsurCsv(path, subjects, err)) << err;
  ASSERT_EQ(subjects.size(), rows.size());
  const int n = static_cast<int>(rows.size());
  EXPECT_EQ(fitMeasure(subjects, Measure::Chest).subjects, n - 3);
  EXPECT_EQ(fitMeasure(subjects, Measure::Waist).subjects, n - 3);
  EXPECT_EQ(fitMeasure(subjects, Measure::Hip).subjects, n - 1);
  EXPECT_EQ(evaluate(subjects, Measure::Chest, fitMeasure(subjects, Measure::Chest)).subjects, n - 3);
  // The remaining rows still follow the exact law.
  EXPECT_NEAR(fitMeasure(subjects, Measure::Waist).weight_exponent, weightExponent(waist), 1e-5);
}

TEST(GirthRegression, CorruptFilesFailWithAMessage) {
  const std::string good = toCsv(syntheticRows(), "\r\n");
  const std::string header = good.substr(0, good.find('\n') + 1);
  const std::string body = good.substr(header.size());
  std::string short_row = good;
  short_row.insert(header.size() + body.find('\n') + 1, "10999,1600,1,2,3\r\n");  // third line
  std::string garbage = header;
  for (int r = 0; r < 3; ++r) {
    garbage += "abc";
    for (int i = 0; i < kMeasureCount + 3; ++i) garbage += ",#VALUE!";
    garbage += "\r\n";
  }

  struct Case {
    const char* name;
    std::string path;
    const char* expected_in_message;
  };
  const Case cases[] = {
      {"nonexistent file", ::testing::TempDir() + "girth_regression_does_not_exist.csv", "cannot open"},
      {"empty file", writeTempFile("empty.csv", ""), "empty"},
      {"blank lines only", writeTempFile("blank.csv", "\r\n\r\n"), "empty"},
      {"missing header", writeTempFile("no_header.csv", body), "header"},
      {"header only", writeTempFile("header_only.csv", header), "no subject"},
      {"wrong column count", writeTempFile("short_row.csv", short_row), "line 3"},
      {"garbage numbers", writeTempFile("garbage.csv", garbage), "no subject"},
      {"binary junk", writeTempFile("junk.csv", std::string("\x00\xff\x01,\n\x7f", 6)), "header"},
  };
  for (const Case& c : cases) {
    std::vector<AnsurSubject> subjects(3);  // must come back empty
    std::string err;
    EXPECT_FALSE(loadAnsurCsv(c.path, subjects, err)) << c.name;
    EXPECT_TRUE(subjects.empty()) << c.name;
    EXPECT_NE(err.find(c.expected_in_message), std::string::npos) << c.name << ": " << err;
  }
}

TEST(GirthRegression, FittingTooLittleDataGivesNoFit) {
  EXPECT_EQ(fitMeasure({}, Measure::Chest).subjects, 0);
  const FitReport empty = evaluate({}, Measure::Chest, ansurCoefficients(Measure::Chest));
  EXPECT_EQ(empty.subjects, 0);
  EXPECT_TRUE(std::isnan(empty.r2));
}

TEST(GirthRegression, CommittedCoefficientsArePresent) {
  for (int i = 0; i < kMeasureCount; ++i) {
    const RegressionCoefficients& c = ansurCoefficients(measureAt(i));
    EXPECT_GT(c.subjects, 900) << measureName(measureAt(i));
    EXPECT_GT(c.residual_sd_log, 0.0) << measureName(measureAt(i));
  }
}

TEST(GirthRegression, PredictionsAreFiniteAndPositiveOverTheWholeDomain) {
  const auto check = [](float h, float w) {
    for (int i = 0; i < kMeasureCount; ++i) {
      const float mm = predictMeasureMm(measureAt(i), h, w);
      ASSERT_TRUE(std::isfinite(mm) && mm > 0.0f) << measureName(measureAt(i)) << " h=" << h << " w=" << w;
    }
  };
  for (float h = kMinHeightM; h <= kMaxHeightM + 1e-4f; h += 0.05f)
    for (float w = kMinWeightKg; w <= kMaxWeightKg + 1e-3f; w += 5.0f) check(h, w);
  for (float h = 1.0f; h <= 2.2f + 1e-4f; h += 0.1f)  // BMI 15..45 at every height
    for (float bmi = 15.0f; bmi <= 45.0f + 1e-3f; bmi += 2.5f) check(h, bmi * h * h);
  const float inf = std::numeric_limits<float>::infinity();
  check(std::nanf(""), 60.0f);
  check(1.7f, std::nanf(""));
  check(inf, -inf);
  check(0.0f, 1e9f);
  // Out-of-domain inputs are clamped to the domain's edge.
  EXPECT_EQ(predictMeasureMm(Measure::Waist, 9.0f, 70.0f), predictMeasureMm(Measure::Waist, kMaxHeightM, 70.0f));
  EXPECT_EQ(predictMeasureMm(Measure::Waist, 1.6f, 1.0f), predictMeasureMm(Measure::Waist, 1.6f, kMinWeightKg));
}

TEST(GirthRegression, GirthsAndTorsoSectionsGrowWithWeight) {
  // Girths plus the depths/breadths the body builder turns into ellipses.
  for (int i = 0; i <= static_cast<int>(Measure::ButtockDepth); ++i) {
    const Measure m = measureAt(i);
    for (float h = 1.0f; h <= 2.2f + 1e-4f; h += 0.1f) {
      float previous = predictMeasureMm(m, h, kMinWeightKg);
      for (float w = kMinWeightKg + 2.5f; w <= kMaxWeightKg + 1e-3f; w += 2.5f) {
        const float mm = predictMeasureMm(m, h, w);
        ASSERT_GT(mm, previous) << measureName(m) << " h=" << h << " w=" << w;
        previous = mm;
      }
    }
  }
}

TEST(GirthRegression, AverageWomanLooksPlausible) {
  // The survey's mean woman (1.627 m, 68.0 kg) against the survey's mean girths (chest 949,
  // waist 865, hip 1023 mm) and the top-down order of the body heights.
  const auto at_mean = [](Measure m) { return predictMeasureMm(m, 1.627f, 68.0f); };
  EXPECT_NEAR(at_mean(Measure::Chest), 949.0f, 20.0f);
  EXPECT_NEAR(at_mean(Measure::Waist), 865.0f, 20.0f);
  EXPECT_NEAR(at_mean(Measure::Hip), 1023.0f, 20.0f);
  EXPECT_LT(at_mean(Measure::KneeHeight), at_mean(Measure::CrotchHeight));
  EXPECT_LT(at_mean(Measure::CrotchHeight), at_mean(Measure::WaistHeight));
  EXPECT_LT(at_mean(Measure::WaistHeight), at_mean(Measure::AcromialHeight));
  EXPECT_LT(at_mean(Measure::AcromialHeight), 1627.0f);
}

// ---- With the real ANSUR II data ------------------------------------------------------------

TEST(GirthRegression, RefitFromCsvReproducesCommittedCoefficients) {
  DRAPE_REQUIRE_SHARED(path, kAnsurFile);
  std::vector<AnsurSubject> subjects;
  std::string err;
  ASSERT_TRUE(loadAnsurCsv(path, subjects, err)) << err;
  EXPECT_EQ(subjects.size(), 993u);
  for (int i = 0; i < kMeasureCount; ++i) {
    const Measure m = measureAt(i);
    const RegressionCoefficients refit = fitMeasure(subjects, m);
    EXPECT_EQ(refit.subjects, ansurCoefficients(m).subjects) << measureName(m);
    for (float h = 1.3f; h <= 2.0f + 1e-4f; h += 0.05f) {
      for (float w = 35.0f; w <= 150.0f + 1e-3f; w += 5.0f) {
        ASSERT_NEAR(predictMm(refit, h, w), predictMeasureMm(m, h, w), 0.5f)
            << measureName(m) << " h=" << h << " w=" << w << ": re-run drape-fit-ansur and paste its output";
      }
    }
  }
}

TEST(GirthRegression, HeldOutAccuracyOfTorsoGirths) {
  DRAPE_REQUIRE_SHARED(path, kAnsurFile);
  std::vector<AnsurSubject> subjects;
  std::string err;
  ASSERT_TRUE(loadAnsurCsv(path, subjects, err)) << err;
  // Measured 5-fold held-out R² (docs/body-shape.md): chest 0.735, waist 0.757, hip 0.845. The
  // bounds leave ~0.035 so other folds or the other data half pass and a broken fit does not.
  struct Bound {
    Measure measure;
    double min_r2, max_mae_percent;
  };
  const Bound bounds[] = {{Measure::Chest, 0.70, 4.5}, {Measure::Waist, 0.72, 5.5}, {Measure::Hip, 0.81, 3.0}};
  for (const Bound& b : bounds) {
    const FitReport held_out = crossValidate(subjects, b.measure, 5);
    const FitReport in_sample = evaluate(subjects, b.measure, ansurCoefficients(b.measure));
    EXPECT_GT(held_out.r2, b.min_r2) << measureName(b.measure);
    EXPECT_LT(held_out.mae_percent, b.max_mae_percent) << measureName(b.measure);
    // Three parameters on ~1000 subjects: held-out should be close to in-sample (no overfit).
    EXPECT_LT(in_sample.r2 - held_out.r2, 0.01) << measureName(b.measure);
  }
}

}  // namespace
}  // namespace drape
