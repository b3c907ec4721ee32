// Scene files (docs/scenes.md). A scene the reader accepts must also survive scene_to_json then
// scene_from_json unchanged: recordings embed scenes that way.
#include "systems/scenes/scene_json.h"
#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = rivulet::fuzz::write_scratch("scene.json", data, size);
    const auto scene = rivulet::fuzz::read_or_reject([&] { return rivulet::load_scene_file(path); });
    if (!scene) return 0;
    const nlohmann::json once = rivulet::scene_to_json(*scene);
    const nlohmann::json twice = rivulet::scene_to_json(rivulet::scene_from_json(once, "round trip"));
    if (once != twice)
        rivulet::fuzz::finding("scene_to_json(scene_from_json(j)) changed j: " + once.dump() + " became " +
                               twice.dump());
    return 0;
}
