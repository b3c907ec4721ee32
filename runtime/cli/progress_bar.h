#pragma once
// A one-line progress bar on stderr. On a terminal it redraws in place; otherwise it prints a line at
// every 10 % so logs stay short. Never allocates while updating.
#include <unistd.h>
#include <cstdio>

namespace rivulet::cli {

class ProgressBar {
  public:
    ProgressBar(const char* label, int total)
        : label_(label), total_(total > 0 ? total : 1), tty_(::isatty(2)) {}

    void update(int done) {
        const int percent = done * 100 / total_;
        if (!tty_) {
            if (percent / 10 == last_decile_ && done != total_) return;
            last_decile_ = percent / 10;
            std::fprintf(stderr, "%s %d/%d (%d%%)\n", label_, done, total_, percent);
            return;
        }
        char bar[41];
        const int filled = done * 40 / total_;
        for (int i = 0; i < 40; ++i) bar[i] = i < filled ? '#' : '.';
        bar[40] = 0;
        std::fprintf(stderr, "\r%s [%s] %d/%d", label_, bar, done, total_);
        if (done == total_) std::fputc('\n', stderr);
        std::fflush(stderr);
    }

  private:
    const char* label_;
    int total_;
    bool tty_;
    int last_decile_ = -1;
};

}  // namespace rivulet::cli
