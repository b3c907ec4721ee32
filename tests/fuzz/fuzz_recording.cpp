// Recordings (docs/recording.md). Mutated bytes almost never keep the XXH3 checksum right, which would
// stop every input at the checksum check; so an input that is a JSON object is read a second time with
// its checksum recomputed, and the fuzzer reaches the checks behind it.
#include <string_view>

#include "jobs/mesh_hash.h"
#include "runtime/lib/recording.h"
#include "tests/fuzz/harness.h"

namespace {

void read(const std::string& path) {
    rivulet::fuzz::read_or_reject([&] { return rivulet::read_recording(path); });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    read(rivulet::fuzz::write_scratch("input.rivrec", data, size));

    // The reader refuses deeper documents anyway, and dump() below recurses once per level.
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    if (rivulet::fuzz::bracket_depth(text) > 64) return 0;
    auto doc = rivulet::fuzz::read_or_reject([&] { return nlohmann::json::parse(text); });
    if (!doc || !doc->is_object()) return 0;
    doc->erase("checksum");
    const std::string body = doc->dump();  // what read_recording hashes: the document without "checksum"
    (*doc)["checksum"] = rivulet::hash_hex(rivulet::hash_bytes(body.data(), body.size()));
    const std::string fixed = doc->dump(1);
    read(rivulet::fuzz::write_scratch("fixed.rivrec", reinterpret_cast<const std::uint8_t*>(fixed.data()),
                                      fixed.size()));
    return 0;
}
