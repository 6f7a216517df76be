#include "sweeps.h"

#include <cstdio>

namespace bench {

namespace {

Setting base(const char* sweep, const std::string& label) {
  Setting s;
  s.sweep = sweep;
  s.label = label;
  return s;
}

std::string hz(float v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g Hz", v);
  return b;
}

void markDefaults(Sweep& sw) {
  const std::string def = Setting{}.key();
  for (Setting& s : sw.settings) s.is_default = s.key() == def;
}

}  // namespace

std::vector<std::string> sweepNames() {
  return {"solver", "substeps", "iterations", "strain_limit", "ring_points", "contact_response",
          "continuous_collision", "resolution", "backend"};
}

std::vector<Sweep> makeSweeps(bool quick, bool with_opencl) {
  std::vector<Sweep> out;
  {
    Sweep sw{"solver", "Solver: XPBD vs the paper's mass-spring", {}};
    sw.settings.push_back(base("solver", "XPBD 300 Hz"));
    Setting m = base("solver", "mass-spring 2880 Hz");
    m.solver = DRAPE_SOLVER_MASS_SPRING;
    m.substep_hz = kMassSpringSubstepHz;
    sw.settings.push_back(m);
    out.push_back(sw);
  }
  {
    Sweep sw{"substeps", "Substeps per simulated second (1 iteration each)", {}};
    const std::vector<float> rates =
        quick ? std::vector<float>{150, 300} : std::vector<float>{60, 120, 150, 300, 600, 1200};
    for (float r : rates) {
      Setting s = base("substeps", hz(r));
      s.substep_hz = r;
      sw.settings.push_back(s);
    }
    out.push_back(sw);
  }
  {
    Sweep sw{"iterations", "Constraint iterations per substep, at 300 Hz and 60 Hz", {}};
    const std::vector<uint32_t> its = quick ? std::vector<uint32_t>{1, 2} : std::vector<uint32_t>{1, 2, 4, 8};
    const std::vector<float> rates = quick ? std::vector<float>{300} : std::vector<float>{300, 60};
    for (float r : rates) {
      for (uint32_t it : its) {
        Setting s = base("iterations", hz(r) + " x " + std::to_string(it));
        s.substep_hz = r;
        s.iterations = it;
        sw.settings.push_back(s);
      }
    }
    out.push_back(sw);
  }
  {
    // drape_cloth_params.strain_limit: structural edges held to rest x (1 + limit) at the end of
    // each step (docs/cloth-solver.md), in strain_limit_passes Gauss-Seidel passes (2 unless the
    // label says; docs/garments.md, "More strain-limit passes").
    Sweep sw{"strain_limit", "Strain limit at the end of each step (structural edges, over rest) and its passes", {}};
    struct Point {
      float limit;
      uint32_t passes;
    };
    const std::vector<Point> points =
        quick ? std::vector<Point>{{0.0f, 2}, {0.1f, 2}, {0.05f, 8}}
              : std::vector<Point>{{0.0f, 2}, {0.05f, 2}, {0.1f, 2}, {0.2f, 2}, {0.05f, 8}, {0.05f, 16}};
    for (const Point& pt : points) {
      char label[48];
      if (!(pt.limit > 0.0f))
        std::snprintf(label, sizeof label, "off");
      else if (pt.passes == Setting{}.strain_limit_passes)
        std::snprintf(label, sizeof label, "%g %%", 100.0 * pt.limit);
      else
        std::snprintf(label, sizeof label, "%g %% x %u passes", 100.0 * pt.limit, pt.passes);
      Setting s = base("strain_limit", label);
      s.strain_limit = pt.limit;
      s.strain_limit_passes = pt.passes;
      sw.settings.push_back(s);
    }
    out.push_back(sw);
  }
  {
    Sweep sw{"ring_points", "Points per feature ring K (proxy fit)", {}};
    const std::vector<uint32_t> ks =
        quick ? std::vector<uint32_t>{12, 20} : std::vector<uint32_t>{8, 12, 16, 20, 32, 48};
    for (uint32_t k : ks) {
      Setting s = base("ring_points", "K " + std::to_string(k));
      s.ring_points = k;
      sw.settings.push_back(s);
    }
    out.push_back(sw);
  }
  {
    Sweep sw{"contact_response", "Proxy contact response", {}};
    Setting r = base("contact_response", "radial");
    r.contact_response = DRAPE_CONTACT_RADIAL;
    sw.settings.push_back(r);
    sw.settings.push_back(base("contact_response", "exact"));
    out.push_back(sw);
  }
  {
    Sweep sw{"continuous_collision", "Continuous (swept) collision", {}};
    sw.settings.push_back(base("continuous_collision", "on"));
    Setting s = base("continuous_collision", "off");
    s.continuous_collision = 0;
    sw.settings.push_back(s);
    out.push_back(sw);
  }
  {
    Sweep sw{"resolution", "Garment resolution (template particles)", {}};
    const std::vector<uint32_t> ns =
        quick ? std::vector<uint32_t>{1000, 2000} : std::vector<uint32_t>{500, 1000, 2000, 4000, 8000};
    for (uint32_t n : ns) {
      Setting s = base("resolution", std::to_string(n) + " particles");
      s.particles = n;
      sw.settings.push_back(s);
    }
    out.push_back(sw);
  }
  {
    Sweep sw{"backend", "Backend", {}};
    sw.settings.push_back(base("backend", "cpu"));
    if (with_opencl) {
      Setting s = base("backend", "opencl");
      s.backend = "opencl";
      sw.settings.push_back(s);
    }
    out.push_back(sw);
  }
  for (Sweep& sw : out) markDefaults(sw);
  return out;
}

}  // namespace bench
