#include "cluster/launcher_env.h"

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <string>

namespace rivulet::cluster {
namespace {

int count_in(const char* name) {
    const char* value = std::getenv(name);
    if (value == nullptr) return 0;
    try {
        return std::max(std::stoi(value), 1);
    } catch (const std::exception&) {
        return 1;  // a launcher started us; how many it did not say
    }
}

}  // namespace

int launcher_world_size() {
    if (const int n = count_in("OMPI_COMM_WORLD_SIZE")) return n;
    if (const int n = count_in("PMI_SIZE")) return n;
    if (std::getenv("PMIX_RANK") != nullptr || std::getenv("PMI_RANK") != nullptr)
        return std::max(count_in("SLURM_NTASKS"), 1);
    return 0;
}

}  // namespace rivulet::cluster
