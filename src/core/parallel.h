// The one thread pool of the project: runs `workers` copies of a worker function, each told its
// index, and joins them. Integration studies hand out replicate tasks through it, the renderer
// rows of pixels. In WebAssembly builds without pthreads it runs one worker on the calling
// thread (the page parallelises over Web Workers instead).
#pragma once

#include <algorithm>
#include <vector>

#if defined(__EMSCRIPTEN__) && !defined(__EMSCRIPTEN_PTHREADS__)
#define MCPLAY_HAS_THREADS 0
#else
#define MCPLAY_HAS_THREADS 1
#include <thread>
#endif

namespace mcp {

/// Runs worker(0) .. worker(workers - 1), concurrently where the build has threads (then on
/// workers - 1 new threads and the calling one); returns when all are done. Without threads only
/// worker(0) runs: callers hand out their work through a shared counter or by worker count, so
/// one worker does everything.
template <class Worker> int run_workers(int workers, Worker&& worker) {
#if MCPLAY_HAS_THREADS
    workers = std::max(1, workers);
    std::vector<std::thread> pool;
    for (int w = 1; w < workers; ++w) pool.emplace_back([&worker, w] { worker(w); });
    worker(0);
    for (std::thread& t : pool) t.join();
    return workers;
#else
    (void)workers;
    worker(0);
    return 1;
#endif
}

} // namespace mcp
