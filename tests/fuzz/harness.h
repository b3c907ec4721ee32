#pragma once
// What every fuzz target shares (docs/fuzzing.md): the readers take a path, so the input goes to a
// scratch file first; and one policy for what a reader may throw.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <typeinfo>
#include <variant>

#include <nlohmann/json.hpp>

#include "systems/io/mesh_io.h"
#include "systems/io/particle_io.h"

namespace rivulet::fuzz {

// This process's scratch folder (under /dev/shm, one per process so parallel fuzzers never share a file),
// created on first use and removed at exit.
const std::string& scratch_dir();

// Writes the input to `<scratch>/<name>` (the extension in `name` picks the reader's format) and returns
// the path. A failed write aborts: the harness, not the reader, would be broken.
std::string write_scratch(std::string_view name, const std::uint8_t* data, std::size_t size);

// A harness check that failed (a round trip that changed the data, a message-less error): prints `what`
// and aborts, which libFuzzer reports as a crash with this input.
[[noreturn]] void finding(const std::string& what);

// Runs `read` and returns its result, or nothing when it throws one of the errors readers document.
//
// The handlers are listed one by one, deliberately without a catch of std::exception: std::bad_alloc and
// std::length_error (a reader sized something by what the header claims, not by the bytes present) then
// find no handler, so std::terminate runs at the throw itself and the crash report's stack shows the
// allocation that asked for too much. The expected errors (the project's FileFormatError and
// RecordingError are std::runtime_error) must carry a message.
template <class Read>
auto read_or_reject(Read&& read) -> std::optional<decltype(read())> {
    auto need_message = [](const std::exception& e) {
        if (std::string_view(e.what()).empty())
            finding(std::string("a reader threw ") + typeid(e).name() + " without a message");
    };
    try {
        return read();
    } catch (const std::runtime_error& e) {  // FileFormatError, RecordingError, filesystem errors
        need_message(e);
    } catch (const std::invalid_argument& e) {  // scene_from_json
        need_message(e);
    } catch (const std::out_of_range& e) {
        need_message(e);
    } catch (const std::domain_error& e) {
        need_message(e);
    } catch (const nlohmann::json::exception& e) {
        need_message(e);
    } catch (const std::bad_optional_access& e) {
        need_message(e);
    } catch (const std::bad_variant_access& e) {
        need_message(e);
    } catch (const std::bad_cast& e) {
        need_message(e);
    }
    return std::nullopt;
}

// Round trips: what a reader accepted, the project's writer must write and the reader read back
// bit-identically (a writer/reader disagreement is a finding). Any exception escapes: it is a finding.
void check_particles_round_trip(const ParticleCloud& cloud);
void check_mesh_round_trip(const MeshData& mesh, std::string_view extension);

// A JSON document's deepest nesting, counting every bracket (also those inside strings, so it may
// overestimate): harness code that re-serializes a document bounds its recursion with this.
int bracket_depth(std::string_view text);

}  // namespace rivulet::fuzz
