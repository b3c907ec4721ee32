// What streaming through memory costs on this machine: b[i] = a[i] * s + b[i] over two arrays far larger
// than the caches (two streams read, one written), split evenly over T threads. A per-particle job whose
// bytes per particle times the particle count, divided by this rate, is far below its measured time is
// bound by its instructions and latencies, not by memory (perf/RESULTS.md, issue 16).
// `--particles N` also sweeps the diffuse update's own streams with no work between the loads and the
// stores: per particle 13 four-byte arrays read, 7 of them written back in place, and a 20-byte sprite
// and a 4-byte key written (jobs/diffuse_update.cpp), in blocks of 16,384 as the update's: the floor of
// that job's milliseconds at N particles, whatever its instructions.
//
//   bench_memory_bandwidth [--threads 1,2] [--mb 256] [--repeat 7] [--particles 1000000]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

namespace {

std::vector<int> parse_list(const std::string& text) {
    std::vector<int> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoi(item));
    return out;
}

// Milliseconds of one sweep over [0, n) split into `threads` even ranges.
double sweep_ms(std::vector<float>& a, std::vector<float>& b, int threads) {
    const std::size_t n = a.size();
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t)
        workers.emplace_back([&, t] {
            const std::size_t lo = n * std::size_t(t) / std::size_t(threads),
                              hi = n * std::size_t(t + 1) / std::size_t(threads);
            for (std::size_t i = lo; i < hi; ++i) b[i] = a[i] * 1.0001f + b[i];
        });
    for (std::thread& w : workers) w.join();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The diffuse update's streams over n particles, blocks of 16,384 taken in turn by `threads` threads.
struct UpdateStreams {
    static constexpr int kRead = 13, kRewritten = 7, kSpriteWords = 5;
    std::vector<std::vector<float>> arrays;
    std::vector<float> sprites;
    std::vector<std::uint32_t> keys;
    explicit UpdateStreams(std::size_t n)
        : arrays(kRead, std::vector<float>(n, 1.0f)), sprites(n * kSpriteWords), keys(n) {}

    double sweep_ms(int threads) {
        constexpr std::size_t kBlock = 16384;
        const std::size_t n = keys.size(), blocks = (n + kBlock - 1) / kBlock;
        std::atomic<std::size_t> next{0};
        const auto start = std::chrono::steady_clock::now();
        std::vector<std::thread> workers;
        for (int t = 0; t < threads; ++t)
            workers.emplace_back([&] {
                for (std::size_t b = next++; b < blocks; b = next++)
                    for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
                        float sum = 0;
                        for (int a = 0; a < kRead; ++a) sum += arrays[std::size_t(a)][i];
                        for (int a = 0; a < kRewritten; ++a) arrays[std::size_t(a)][i] = sum;
                        for (int w = 0; w < kSpriteWords; ++w)
                            sprites[i * kSpriteWords + std::size_t(w)] = sum;
                        keys[i] = static_cast<std::uint32_t>(sum);
                    }
            });
        for (std::thread& w : workers) w.join();
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
};

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Memory bandwidth: b = a * s + b over two large arrays, per thread count"};
    std::string threads_text = "1,2";
    int mb = 256, repeat = 7, particles = 0;
    app.add_option("--threads", threads_text, "Comma-separated thread counts");
    app.add_option("--mb", mb, "Megabytes per array")->check(CLI::Range(16, 8192));
    app.add_option("--repeat", repeat, "Sweeps per thread count (the median is printed)")
        ->check(CLI::Range(1, 1000));
    app.add_option("--particles", particles,
                   "Also sweep the diffuse update's streams for this many particles")
        ->check(CLI::Range(0, 50000000));
    CLI11_PARSE(app, argc, argv);
    std::vector<int> thread_counts;
    try {
        thread_counts = parse_list(threads_text);
    } catch (const std::exception&) {
        std::fprintf(stderr, "--threads: expected comma-separated counts, got '%s'\n", threads_text.c_str());
        return 2;
    }
    const std::size_t n = std::size_t(mb) * (1u << 20) / sizeof(float);
    std::vector<float> a(n, 1.0f), b(n, 2.0f);
    std::printf("%d MB per array; bytes moved per sweep: two arrays read, one written\n", mb);
    std::printf("threads  median ms     GB/s\n");
    for (const int threads : thread_counts) {
        if (threads < 1 || threads > 256) {
            std::fprintf(stderr, "--threads: %d is not between 1 and 256\n", threads);
            return 2;
        }
        std::vector<double> ms;
        for (int r = 0; r < repeat; ++r) ms.push_back(sweep_ms(a, b, threads));
        std::sort(ms.begin(), ms.end());
        const double median = ms[ms.size() / 2];
        std::printf("%7d %10.2f %8.1f\n", threads, median, 3.0 * double(n) * sizeof(float) / median / 1e6);
    }
    if (particles == 0) return 0;
    UpdateStreams streams(static_cast<std::size_t>(particles));
    std::printf(
        "\nthe diffuse update's streams, %d particles (13 arrays read, 7 written back, 24 bytes written)\n",
        particles);
    std::printf("threads  median ms\n");
    for (const int threads : thread_counts) {
        std::vector<double> ms;
        for (int r = 0; r < repeat; ++r) ms.push_back(streams.sweep_ms(threads));
        std::sort(ms.begin(), ms.end());
        std::printf("%7d %10.2f\n", threads, ms[ms.size() / 2]);
    }
    return 0;
}
