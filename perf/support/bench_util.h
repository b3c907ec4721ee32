#pragma once
// Small helpers the pass benchmarks share.
#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rivulet::bench {

inline double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// "a,b,,c" -> {"a", "b", "c"}
inline std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

// "8000,24000" -> {8000, 24000}: positive whole numbers; anything else throws std::invalid_argument
// naming `what`.
inline std::vector<long> parse_list(std::string_view s, const char* what) {
    std::vector<long> v;
    while (!s.empty()) {
        const std::size_t comma = s.find(',');
        const std::string item(s.substr(0, comma));
        char* end = nullptr;
        const long x = std::strtol(item.c_str(), &end, 10);
        if (item.empty() || *end != '\0' || x <= 0)
            throw std::invalid_argument("bad " + std::string(what) + " '" + item + "'");
        v.push_back(x);
        if (comma == std::string_view::npos) break;
        s.remove_prefix(comma + 1);
    }
    if (v.empty()) throw std::invalid_argument("empty " + std::string(what));
    return v;
}

}  // namespace rivulet::bench
