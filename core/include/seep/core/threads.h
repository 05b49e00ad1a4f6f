// How many threads the core's parallel loops (its thread team, core/src/core_team.h; the count is
// OpenMP's setting) use on the calling thread. Results do not depend on it (every parallel loop
// is bit-identical on any thread count); only speed does. A job service that runs several jobs
// at once gives each its share of the cores: two jobs of two threads each on two cores wait at
// every barrier for a descheduled thread, which was measured to slow a coupled step down up to
// 100x.
#pragma once

namespace seep::core {

// Sets the thread count of the core's parallel loops started from the calling thread (>= 1).
void SetCoreThreadsForThisThread(int threads);

// For tests: loops over at least `items` items (instead of the core's threshold, 8,192) go to
// the calling thread's team, so that a scene of a few hundred disks takes the same parallel paths
// a large one does. Results must not change (every parallel loop is bit-identical on any thread
// count); a thread-count test over small generated scenes sets it to check that they do not.
// items <= 0 restores the core's threshold.
void SetMinParallelItemsForThisThread(long items);

// The cores of this machine shared out among `concurrent_jobs` jobs: max(1, cores / jobs).
int CoreThreadsPerJob(int concurrent_jobs);

}  // namespace seep::core
