#include "cluster/frame_batch.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "cluster/gather_arrays.h"

namespace rivulet::cluster {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kAskTag = 1;     // rank -> 0: the frame it finished, or -1 at its first request
constexpr int kAnswerTag = 2;  // 0 -> rank: the next frame, or -1 when there is none
constexpr int kNoFrame = -1;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

FrameOutcome timed(int index, int rank, const std::function<FrameOutcome(int)>& mesh_frame) {
    const auto start = Clock::now();
    FrameOutcome out = mesh_frame(index);
    out.index = index, out.rank = rank;
    out.seconds = seconds_since(start);
    return out;
}

// Rank 0's second thread: answers every other rank's requests from the counter rank 0's own frames
// also draw from, until each rank has been told there is nothing left. It polls (MPI_Test, then a short
// sleep) rather than blocking in MPI_Recv, which would spin a core the meshing threads need.
void hand_out_frames(MPI_Comm comm, int ranks, int count, std::atomic<int>& next,
                     const std::function<void()>& frame_done) {
    int idle_ranks = 0;
    while (idle_ranks < ranks - 1) {
        int finished = kNoFrame;
        MPI_Request request;
        MPI_Irecv(&finished, 1, MPI_INT, MPI_ANY_SOURCE, kAskTag, comm, &request);
        MPI_Status status;
        for (int arrived = 0;;) {
            MPI_Test(&request, &arrived, &status);
            if (arrived) break;
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        if (finished != kNoFrame) frame_done();
        int frame = next.fetch_add(1);
        if (frame >= count) frame = kNoFrame, ++idle_ranks;
        MPI_Send(&frame, 1, MPI_INT, status.MPI_SOURCE, kAnswerTag, comm);
    }
}

std::string pack(const std::vector<FrameOutcome>& outcomes) {
    nlohmann::json list = nlohmann::json::array();
    for (const FrameOutcome& o : outcomes)
        list.push_back({{"index", o.index},
                        {"rank", o.rank},
                        {"ok", o.ok},
                        {"error", o.error},
                        {"seconds", o.seconds},
                        {"record", o.record}});
    return list.dump();
}

void unpack(const std::string& text, std::vector<FrameOutcome>& into) {
    for (const nlohmann::json& j : nlohmann::json::parse(text))
        into.push_back({j.at("index").get<int>(), j.at("rank").get<int>(), j.at("ok").get<bool>(),
                        j.at("error").get<std::string>(), j.at("seconds").get<double>(),
                        j.at("record").get<std::string>()});
}

// Every rank's outcomes at rank 0, in frame order.
std::vector<FrameOutcome> gather(const MpiSession& session, const std::vector<FrameOutcome>& mine) {
    const std::string text = pack(mine);
    std::vector<FrameOutcome> outcomes;
    for (const std::vector<char>& rank :
         gather_arrays(session, std::vector<char>(text.begin(), text.end()), MPI_CHAR, "frame records"))
        unpack(std::string(rank.begin(), rank.end()), outcomes);
    std::sort(outcomes.begin(), outcomes.end(),
              [](const FrameOutcome& a, const FrameOutcome& b) { return a.index < b.index; });
    return outcomes;
}

}  // namespace

BatchResult run_frames_over_ranks(const MpiSession& session, int count,
                                  const std::function<FrameOutcome(int)>& mesh_frame,
                                  const std::function<void(int)>& progress) {
    const auto start = Clock::now();
    const int rank = session.rank();
    std::vector<FrameOutcome> mine;
    if (rank == 0) {
        std::atomic<int> next{0};
        std::mutex progress_mutex;
        int done = 0;
        const auto frame_done = [&] {
            const std::lock_guard lock(progress_mutex);
            progress(++done);
        };
        std::thread dealer;
        if (session.size() > 1)
            dealer = std::thread(hand_out_frames, session.comm(), session.size(), count, std::ref(next),
                                 std::cref(frame_done));
        for (int frame; (frame = next.fetch_add(1)) < count;) {
            mine.push_back(timed(frame, rank, mesh_frame));
            frame_done();
        }
        if (dealer.joinable()) dealer.join();
    } else {
        int finished = kNoFrame;
        for (;;) {
            MPI_Send(&finished, 1, MPI_INT, 0, kAskTag, session.comm());
            int frame = kNoFrame;
            MPI_Recv(&frame, 1, MPI_INT, 0, kAnswerTag, session.comm(), MPI_STATUS_IGNORE);
            if (frame == kNoFrame) break;
            mine.push_back(timed(frame, rank, mesh_frame));
            finished = frame;
        }
    }
    BatchResult result;
    result.wall_seconds = seconds_since(start);
    result.frames = gather(session, mine);
    if (rank == 0) {
        result.ranks.resize(static_cast<std::size_t>(session.size()));
        for (const FrameOutcome& o : result.frames) {
            RankLoad& load = result.ranks[static_cast<std::size_t>(o.rank)];
            ++load.frames, load.busy_seconds += o.seconds;
            result.failed += o.ok ? 0 : 1;
        }
    }
    MPI_Bcast(&result.failed, 1, MPI_INT, 0, session.comm());
    return result;
}

}  // namespace rivulet::cluster
