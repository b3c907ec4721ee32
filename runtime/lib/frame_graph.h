#pragma once
// A frame's dependency graph of named jobs on oneTBB (tbb::flow::graph). Built once, re-run every frame
// without allocating. A job is either serial or a set of independent items the runtime splits across
// workers; jobs know nothing about threads. Each run records every job's start and end (µs from the
// frame's start) so stages can be timed and traced.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

namespace rivulet {

class TraceRecorder;

class FrameGraph {
  public:
    using JobId = std::uint32_t;
    using SerialFn = std::function<void()>;
    using CountFn = std::function<std::size_t()>;
    using ItemFn = std::function<void(std::size_t item)>;

    FrameGraph();
    ~FrameGraph();
    FrameGraph(const FrameGraph&) = delete;
    FrameGraph& operator=(const FrameGraph&) = delete;

    JobId serial(std::string name, SerialFn fn, std::initializer_list<JobId> after = {});
    // `count` is asked when the job starts (item counts change per frame); items run in any order.
    JobId parallel(std::string name, CountFn count, ItemFn item, std::initializer_list<JobId> after = {});
    // A job that a serial job runs from inside its body, any number of times per frame: for loops the
    // static graph cannot express (SPH substeps). Timed and traced like other jobs; its time is the sum
    // over the frame's calls. `parent` is the serial job that calls run_nested for it.
    JobId nested(std::string name, JobId parent);
    // From inside `parent`'s body: runs items [0, n) of nested job `j` on the workers and returns when all
    // are done. `item` is called as item(std::size_t); it is not copied, so nothing allocates.
    template <class F>
    void run_nested(JobId j, std::size_t n, F&& item) {
        using Fn = std::remove_reference_t<F>;
        void* fn = const_cast<void*>(static_cast<const void*>(std::addressof(item)));
        run_nested_items(j, n, ItemRef{fn, [](void* f, std::size_t i) { (*static_cast<Fn*>(f))(i); }});
    }

    // A job that throws stops the frame's remaining jobs; wait() rethrows the first exception.
    // Starts the jobs without dependencies and returns: TBB workers run the frame while the caller does
    // other work (rendering). wait() joins; the caller helps with the remaining jobs.
    void start();
    void wait();
    void run() {
        start();
        wait();
    }

    // Records a zone per serial job and per item of a parallel job into `recorder` (null: off).
    void attach_trace(TraceRecorder* recorder);
    // The frame number the next run's zones carry.
    void set_frame(std::uint32_t frame) { frame_ = frame; }

    std::size_t job_count() const { return jobs_.size(); }
    // Items run in parallel: a parallel job, or a nested one (run_nested always runs items).
    bool job_parallel(JobId j) const { return !jobs_[j].serial; }
    // The graph in Graphviz DOT (`rivulet run --graph FILE.dot`): a box per job, parallel ones marked
    // "name*" on a stacked box, an arrow per dependency, and a dashed arrow from a serial job to each
    // nested job its body runs.
    std::string dot() const;
    const std::string& job_name(JobId j) const { return jobs_[j].name; }
    const std::vector<JobId>& job_after(JobId j) const { return jobs_[j].after; }
    // The job whose body runs nested job `j`; -1 for jobs of the graph itself.
    std::int64_t job_parent(JobId j) const { return jobs_[j].parent; }
    // Last run: job start/end in µs since start(), and items processed.
    double job_begin_us(JobId j) const { return jobs_[j].begin_us; }
    double job_end_us(JobId j) const { return jobs_[j].end_us; }
    double job_ms(JobId j) const { return (jobs_[j].end_us - jobs_[j].begin_us) * 1e-3; }
    std::size_t job_items(JobId j) const { return jobs_[j].items; }
    // Wall time of the last run from start() until its last job finished, ms.
    double last_run_ms() const;

  private:
    struct ItemRef {
        void* fn;
        void (*call)(void*, std::size_t);
    };
    void run_nested_items(JobId j, std::size_t n, ItemRef item);

    struct Job {
        std::string name;
        SerialFn serial;
        CountFn count;
        ItemFn item;
        std::vector<JobId> after;
        double begin_us = 0, end_us = 0;
        std::size_t items = 0;
        std::uint16_t trace_name = 0;
        std::int64_t parent = -1;
    };
    void execute(JobId j);
    void run_job(Job& job);
    void build();

    std::vector<Job> jobs_;
    struct Tbb;
    std::unique_ptr<Tbb> tbb_;
    std::chrono::steady_clock::time_point t0_;
    TraceRecorder* trace_ = nullptr;
    std::uint32_t frame_ = 0;
    std::atomic<bool> failed_{false};
    std::mutex error_mutex_;
    std::exception_ptr error_;
};

}  // namespace rivulet
