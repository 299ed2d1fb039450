// Progress reporting for long io work (reading a layer, building, running many queries).
//
// A Progress is called with the fraction done in [0, 1], from the thread doing the work, a
// bounded number of times (about once per percent). An empty function means nobody is
// watching; the library never draws anything itself, the command line decides whether a bar
// is shown (only on a terminal, and not with -q).
#pragma once

#include <functional>

namespace loci::io {

using Progress = std::function<void(double fraction)>;

// Calls `progress` when `done / total` has moved by at least a percent since the last call.
class ProgressTicker {
 public:
  ProgressTicker(const Progress& progress, double total) : progress_(progress), total_(total) {}
  void tick(double done) {
    if (!progress_ || total_ <= 0) return;
    const double f = done / total_;
    if (f >= last_ + 0.01 || f >= 1.0) {
      last_ = f;
      progress_(f > 1 ? 1.0 : f);
    }
  }

 private:
  const Progress& progress_;
  double total_;
  double last_ = -1;
};

}  // namespace loci::io
