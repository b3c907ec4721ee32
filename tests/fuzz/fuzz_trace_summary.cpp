// Chrome-trace captures for `rivulet trace-summary` (docs/tracing.md): validation, the summary, and its
// text.
#include "runtime/lib/trace_summary.h"
#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = rivulet::fuzz::write_scratch("trace.json", data, size);
    if (const auto s = rivulet::fuzz::read_or_reject([&] { return rivulet::summarize_trace_file(path); }))
        (void)rivulet::format_trace_summary(*s);
    return 0;
}
