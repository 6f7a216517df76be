#include "plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <numeric>

namespace bench {

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

bool haveGnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

// Gnuplot strings are single-quoted: double any quote inside.
std::string quoted(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("''") : std::string(1, c);
  return o + "'";
}

}  // namespace

std::vector<size_t> paretoFront(const std::vector<double>& time, const std::vector<double>& error) {
  std::vector<size_t> order(time.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return time[a] != time[b] ? time[a] < time[b] : error[a] < error[b]; });
  std::vector<size_t> front;
  double best = INFINITY;
  for (size_t i : order) {
    if (!std::isfinite(time[i]) || !std::isfinite(error[i])) continue;
    if (error[i] < best) {  // faster points all had more error: this one is not dominated
      front.push_back(i);
      best = error[i];
    }
  }
  return front;
}

bool plotSweep(const std::string& dir, const std::string& stem, const std::string& title, const std::vector<Row>& rows,
               std::string& note) {
  const std::string dat = dir + "/" + stem + ".dat", gp = dir + "/" + stem + ".gp", png = dir + "/" + stem + ".png";
  // One block per take (gnuplot index), each with: time, deviation, penetration, default flag, label;
  // then per take the two Pareto fronts.
  std::map<std::string, std::vector<const Row*>> by_take;
  std::vector<std::string> takes;
  for (const Row& r : rows) {
    if (!by_take.count(r.take)) takes.push_back(r.take);
    by_take[r.take].push_back(&r);
  }
  {
    std::unique_ptr<std::FILE, FileCloser> f(std::fopen(dat.c_str(), "w"));
    if (!f) {
      note = "cannot write " + dat;
      return false;
    }
    for (const std::string& t : takes) {
      const std::vector<const Row*>& rs = by_take[t];
      std::vector<double> time, dev, pen;
      for (const Row* r : rs) {
        time.push_back(r->frame.median);
        dev.push_back(r->dev_rms_mm);
        pen.push_back(r->pen_p99_mm);
      }
      std::fprintf(f.get(), "# take %s: frame_ms dev_rms_mm pen_p99_mm is_default label\n", t.c_str());
      for (const Row* r : rs)
        std::fprintf(f.get(), "%.5g %.5g %.5g %d \"%s\"\n", r->frame.median, r->dev_rms_mm, r->pen_p99_mm,
                     r->setting.is_default ? 1 : 0, r->setting.label.c_str());
      std::fputs("\n\n", f.get());
      for (const std::vector<double>* err : {&dev, &pen}) {
        std::fprintf(f.get(), "# Pareto front (%s)\n", err == &dev ? "deviation" : "penetration");
        for (size_t i : paretoFront(time, *err)) std::fprintf(f.get(), "%.5g %.5g\n", time[i], (*err)[i]);
        std::fputs("\n\n", f.get());
      }
    }
  }
  {
    std::unique_ptr<std::FILE, FileCloser> f(std::fopen(gp.c_str(), "w"));
    if (!f) {
      note = "cannot write " + gp;
      return false;
    }
    std::fprintf(f.get(),
                 "set terminal pngcairo noenhanced size 1400,560 font 'DejaVu Sans,10'\nset output %s\n"
                 "set multiplot layout 1,2 title %s\nset grid\nset key top right\n"
                 "set xlabel 'whole frame, median ms (push + update + cloth)'\nset offsets graph 0.05, graph 0.2, "
                 "graph 0.1, graph 0\nset yrange [0:*]\n",
                 quoted(png).c_str(), quoted(title).c_str());
    // Times spanning more than a decade (the mass-spring solver, 8 000 particles) on a log axis.
    double lo = INFINITY, hi = 0.0;
    for (const Row& r : rows) {
      lo = std::min(lo, r.frame.median);
      hi = std::max(hi, r.frame.median);
    }
    if (lo > 0.0 && hi / lo > 10.0) std::fputs("set logscale x\n", f.get());
    const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
    for (int panel = 0; panel < 2; ++panel) {
      std::fprintf(f.get(), "set ylabel %s\n",
                   quoted(panel == 0 ? "RMS deviation from the converged reference, mm"
                                     : "P99 penetration into the body mesh, mm")
                       .c_str());
      std::string cmd = "plot ";
      for (size_t t = 0; t < takes.size(); ++t) {
        const std::string c = colours[t % 4];
        const int block = static_cast<int>(3 * t);
        const int col = panel == 0 ? 2 : 3;
        char b[1024];
        std::snprintf(b, sizeof b,
                      "%s%s index %d using 1:%d with points pt 7 ps 1.2 lc rgb '%s' title %s, "
                      "'' index %d using 1:%d:5 with labels offset 0.6,0.6 left font ',8' tc rgb '%s' notitle, "
                      "'' index %d using 1:%d with lines lw 2 dt 2 lc rgb '%s' title 'Pareto front', "
                      "'' index %d using 1:($4 == 1 ? $%d : 1/0) with points pt 6 ps 3 lw 2 lc rgb 'black' "
                      "title %s",
                      t == 0 ? "" : ", ", t == 0 ? quoted(dat).c_str() : "''", block, col, c.c_str(),
                      quoted(takes[t]).c_str(), block, col, c.c_str(), block + 1 + panel, 2, c.c_str(), block, col,
                      t == 0 ? "'default setting'" : "''");
        cmd += b;
      }
      std::fprintf(f.get(), "%s\n", cmd.c_str());
    }
    std::fputs("unset multiplot\n", f.get());
  }
  if (!haveGnuplot()) {
    note = "gnuplot not found (Debian: gnuplot-nox): wrote " + gp + " but no PNG";
    return false;
  }
  const std::string cmd = "gnuplot " + quoted(gp) + " 2>" + quoted(dir + "/" + stem + ".gnuplot.log");
  if (std::system(cmd.c_str()) != 0) {
    note = "gnuplot failed on " + gp + " (see " + stem + ".gnuplot.log)";
    return false;
  }
  return true;
}

}  // namespace bench
