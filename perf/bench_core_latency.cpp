// How far apart two cores are: the round trip of one cache line bounced between them (both threads
// spinning) and of a sleeping thread woken through a condition variable. A frame of scan conversion
// lasts a few hundred microseconds and hands data between workers a dozen times, so these two figures
// decide how well it can scale on a machine; perf/RESULTS.md quotes them next to the 2-thread figures.
//
//   bench_core_latency [--cpus A,B] [--rounds 200000] [--repeat 5]
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

bool pin_to(int cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

// Nanoseconds per round trip of a cache line between the two cores, both threads spinning.
double spin_round_trip_ns(int a, int b, int rounds) {
    alignas(64) std::atomic<int> turn{0};
    std::thread other([&] {
        pin_to(b);
        for (int i = 0; i < rounds; ++i) {
            while (turn.load(std::memory_order_acquire) != 2 * i + 1) {
            }
            turn.store(2 * i + 2, std::memory_order_release);
        }
    });
    pin_to(a);
    const auto t0 = Clock::now();
    for (int i = 0; i < rounds; ++i) {
        turn.store(2 * i + 1, std::memory_order_release);
        while (turn.load(std::memory_order_acquire) != 2 * i + 2) {
        }
    }
    const auto t1 = Clock::now();
    other.join();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / rounds;
}

// Microseconds per round trip when each side sleeps until the other wakes it.
double wake_round_trip_us(int a, int b, int rounds) {
    std::mutex m;
    std::condition_variable cv;
    int turn = 0;
    std::thread other([&] {
        pin_to(b);
        for (int i = 0; i < rounds; ++i) {
            std::unique_lock lock(m);
            cv.wait(lock, [&] { return turn == 1; });
            turn = 0;
            cv.notify_one();
        }
    });
    pin_to(a);
    const auto t0 = Clock::now();
    for (int i = 0; i < rounds; ++i) {
        std::unique_lock lock(m);
        turn = 1;
        cv.notify_one();
        cv.wait(lock, [&] { return turn == 0; });
    }
    const auto t1 = Clock::now();
    other.join();
    return std::chrono::duration<double, std::micro>(t1 - t0).count() / rounds;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

int usage(const char* self) {
    std::fprintf(stderr, "usage: %s [--cpus A,B] [--rounds 200000] [--repeat 5]\n", self);
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    int a = 0, b = 1, rounds = 200000, repeat = 5;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (i + 1 >= argc) return usage(argv[0]);
        const char* value = argv[++i];
        if (arg == "--cpus") {
            if (std::sscanf(value, "%d,%d", &a, &b) != 2) return usage(argv[0]);
        } else if (arg == "--rounds") {
            rounds = std::atoi(value);
        } else if (arg == "--repeat") {
            repeat = std::atoi(value);
        } else {
            return usage(argv[0]);
        }
    }
    const int cpus = static_cast<int>(std::thread::hardware_concurrency());
    if (a < 0 || b < 0 || a >= cpus || b >= cpus || a == b || rounds < 1 || repeat < 1) {
        std::fprintf(stderr, "bench_core_latency: need two different CPUs below %d, rounds and repeat >= 1\n",
                     cpus);
        return 2;
    }
    std::vector<double> spin, wake;
    for (int r = 0; r < repeat; ++r) {
        spin.push_back(spin_round_trip_ns(a, b, rounds));
        wake.push_back(wake_round_trip_us(a, b, std::max(1, rounds / 20)));
    }
    std::printf("| CPUs | cache-line round trip (ns) | wake-up round trip (us) |\n|---|---:|---:|\n");
    std::printf("| %d,%d | %.0f | %.1f |\n", a, b, median(spin), median(wake));
    std::printf("(medians of %d runs; %d spin rounds, %d wake rounds each)\n", repeat, rounds,
                std::max(1, rounds / 20));
    return 0;
}
