#include "seep/core/threads.h"

#include <omp.h>

#include <algorithm>
#include <thread>

#include "parallel_threshold.h"

namespace seep::core {

void SetCoreThreadsForThisThread(int threads) { omp_set_num_threads(std::max(1, threads)); }

void SetMinParallelItemsForThisThread(long items) {
  internal::tl_min_parallel_items = items > 0 ? items : internal::kMinParallelItems;
}

int CoreThreadsPerJob(int concurrent_jobs) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, concurrent_jobs));
}

}  // namespace seep::core
