#include "runtime/lib/frame_graph.h"

#include <fmt/format.h>

#include "runtime/lib/trace_recorder.h"

#include <tbb/blocked_range.h>
#include <tbb/flow_graph.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <stdexcept>

namespace rivulet {

struct FrameGraph::Tbb {
    tbb::flow::graph graph;
    tbb::flow::broadcast_node<tbb::flow::continue_msg> start{graph};
    std::vector<std::unique_ptr<tbb::flow::continue_node<tbb::flow::continue_msg>>> nodes;
};

FrameGraph::FrameGraph() = default;
FrameGraph::~FrameGraph() {
    if (tbb_) tbb_->graph.wait_for_all();
}

FrameGraph::JobId FrameGraph::serial(std::string name, SerialFn fn, std::initializer_list<JobId> after) {
    if (tbb_) throw std::logic_error("FrameGraph: jobs must be added before the first run");
    jobs_.push_back({std::move(name), std::move(fn), {}, {}, std::vector<JobId>(after)});
    return static_cast<JobId>(jobs_.size() - 1);
}

FrameGraph::JobId FrameGraph::parallel(std::string name, CountFn count, ItemFn item,
                                       std::initializer_list<JobId> after) {
    if (tbb_) throw std::logic_error("FrameGraph: jobs must be added before the first run");
    jobs_.push_back({std::move(name), {}, std::move(count), std::move(item), std::vector<JobId>(after)});
    return static_cast<JobId>(jobs_.size() - 1);
}

FrameGraph::JobId FrameGraph::nested(std::string name, JobId parent) {
    if (tbb_) throw std::logic_error("FrameGraph: jobs must be added before the first run");
    if (parent >= jobs_.size() || !jobs_[parent].serial || jobs_[parent].parent >= 0)
        throw std::logic_error("FrameGraph: a nested job's parent must be a serial job of the graph");
    jobs_.push_back({std::move(name), {}, {}, {}, {}});
    jobs_.back().parent = parent;
    return static_cast<JobId>(jobs_.size() - 1);
}

std::string FrameGraph::dot() const {
    std::string out = "digraph frame {\n  rankdir=TB;\n  node [shape=box, fontname=\"monospace\"];\n";
    auto to = std::back_inserter(out);
    for (JobId j = 0; j < jobs_.size(); ++j) {
        if (job_parallel(j))
            fmt::format_to(to, "  j{} [label=\"{}*\", style=\"filled\", shape=box3d];\n", j, jobs_[j].name);
        else
            fmt::format_to(to, "  j{} [label=\"{}\", shape=box];\n", j, jobs_[j].name);
    }
    for (JobId j = 0; j < jobs_.size(); ++j) {
        for (const JobId a : jobs_[j].after) fmt::format_to(to, "  j{} -> j{};\n", a, j);
        if (jobs_[j].parent >= 0) fmt::format_to(to, "  j{} -> j{} [style=dashed];\n", jobs_[j].parent, j);
    }
    out += "}\n";
    return out;
}

void FrameGraph::run_nested_items(JobId j, std::size_t n, ItemRef item) {
    using us = std::chrono::duration<double, std::micro>;
    Job& job = jobs_[j];
    const auto t_begin = std::chrono::steady_clock::now();
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const std::int64_t t = trace_ ? trace_->now_ns() : 0;
                item.call(item.fn, i);
                if (trace_)
                    trace_->record(job.trace_name, frame_, static_cast<std::int32_t>(i), t, trace_->now_ns());
            }
        });
    // Nested jobs keep begin_us at 0 and end_us as their summed time, so job_ms() is that sum.
    job.end_us += us(std::chrono::steady_clock::now() - t_begin).count();
    job.items += n;
}

void FrameGraph::execute(JobId j) {
    Job& job = jobs_[j];
    job.items = 0;
    if (failed_.load(std::memory_order_acquire)) {  // a job upstream threw: skip the rest of the frame
        job.begin_us = job.end_us = 0;
        return;
    }
    try {
        run_job(job);
    } catch (...) {
        std::lock_guard lock(error_mutex_);
        if (!error_) error_ = std::current_exception();
        failed_.store(true, std::memory_order_release);
    }
}

void FrameGraph::attach_trace(TraceRecorder* recorder) {
    if (tbb_) throw std::logic_error("FrameGraph: attach the trace before the first run");
    trace_ = recorder;
    if (trace_)
        for (Job& job : jobs_) job.trace_name = trace_->intern(job.name);
}

void FrameGraph::run_job(Job& job) {
    using us = std::chrono::duration<double, std::micro>;
    job.begin_us = us(std::chrono::steady_clock::now() - t0_).count();
    if (job.serial) {
        const std::int64_t t = trace_ ? trace_->now_ns() : 0;
        job.serial();
        job.items = 1;
        if (trace_) trace_->record(job.trace_name, frame_, -1, t, trace_->now_ns());
    } else {
        const std::size_t n = job.count();
        job.items = n;
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, n, 1), [&job, this](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                    if (!trace_) {
                        job.item(i);
                        continue;
                    }
                    const std::int64_t t = trace_->now_ns();
                    job.item(i);
                    trace_->record(job.trace_name, frame_, static_cast<std::int32_t>(i), t, trace_->now_ns());
                }
            });
    }
    job.end_us = us(std::chrono::steady_clock::now() - t0_).count();
}

void FrameGraph::build() {
    tbb_ = std::make_unique<Tbb>();
    for (JobId j = 0; j < jobs_.size(); ++j) {
        tbb_->nodes.push_back(std::make_unique<tbb::flow::continue_node<tbb::flow::continue_msg>>(
            tbb_->graph, [this, j](const tbb::flow::continue_msg&) { execute(j); }));
    }
    for (JobId j = 0; j < jobs_.size(); ++j) {
        if (jobs_[j].parent >= 0) continue;  // runs inside its parent, not as a node of its own
        if (jobs_[j].after.empty()) tbb::flow::make_edge(tbb_->start, *tbb_->nodes[j]);
        for (JobId d : jobs_[j].after) {
            if (d >= j) throw std::logic_error("FrameGraph: a job may only follow jobs added before it");
            if (jobs_[d].parent >= 0) throw std::logic_error("FrameGraph: a job cannot follow a nested job");
            tbb::flow::make_edge(*tbb_->nodes[d], *tbb_->nodes[j]);
        }
    }
}

void FrameGraph::start() {
    if (!tbb_) build();
    failed_ = false;
    error_ = nullptr;
    for (Job& job : jobs_)
        if (job.parent >= 0) job.begin_us = job.end_us = 0, job.items = 0;
    t0_ = std::chrono::steady_clock::now();
    tbb_->start.try_put(tbb::flow::continue_msg());
}

void FrameGraph::wait() {
    tbb_->graph.wait_for_all();
    if (error_) std::rethrow_exception(error_);
}

double FrameGraph::last_run_ms() const {
    double end = 0;
    for (const Job& j : jobs_) end = std::max(end, j.end_us);
    return end * 1e-3;
}

}  // namespace rivulet
