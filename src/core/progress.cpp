#include "ctid/core/progress.hpp"

#include <utility>

namespace ctid {

namespace {
thread_local ProgressCallback g_callback;
thread_local bool g_stop = false;
}  // namespace

ProgressScope::ProgressScope(ProgressCallback callback) : previous_(std::move(g_callback)), previous_stop_(g_stop) {
  g_callback = std::move(callback);
  g_stop = false;
}

ProgressScope::~ProgressScope() {
  g_callback = std::move(previous_);
  g_stop = previous_stop_;
}

bool report_progress(const char* stage, int iteration, double cost) {
  if (g_stop) return false;
  if (!g_callback) return true;
  g_stop = !g_callback(ProgressEvent{stage, iteration, cost});
  return !g_stop;
}

bool interrupt_requested() { return g_stop; }

}  // namespace ctid
