#pragma once
// Strict JSON <-> struct for settings files, scenes and recordings. A struct lists its fields once in a
// `members(T&, F)` function found by argument-dependent lookup; the reader and writer both walk that
// list, so they cannot drift apart. Reading rejects unknown keys, wrong types and non-finite or
// out-of-range numbers with an error naming the key path; keys left out keep the value already there.
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "jobs/vec3.h"

namespace rivulet::json_fields {

using nlohmann::json;

[[noreturn]] inline void fail(const std::string& where, const std::string& what) {
    throw std::invalid_argument(where + ": " + what);
}

template <class T>
void read(const json& j, T& out, const std::string& where);

inline void read(const json& j, float& out, const std::string& where) {
    if (!j.is_number()) fail(where, "expected a number");
    const double v = j.get<double>();
    if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max()))
        fail(where, "expected a finite number");
    out = static_cast<float>(v);
}
template <class I>
requires std::is_integral_v<I>
void read_integer(const json& j, I& out, const std::string& where) {
    if (!j.is_number_integer()) fail(where, "expected an integer");
    if constexpr (std::is_unsigned_v<I>) {
        if (j.is_number_unsigned() || j.get<std::int64_t>() >= 0) {
            const std::uint64_t v = j.get<std::uint64_t>();
            if (v > std::numeric_limits<I>::max()) fail(where, "integer out of range");
            out = static_cast<I>(v);
            return;
        }
        fail(where, "expected a non-negative integer");
    } else {
        if (j.is_number_unsigned() && j.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<I>::max()))
            fail(where, "integer out of range");
        const std::int64_t v = j.get<std::int64_t>();
        if (v < std::numeric_limits<I>::min() || v > std::numeric_limits<I>::max())
            fail(where, "integer out of range");
        out = static_cast<I>(v);
    }
}
inline void read(const json& j, int& out, const std::string& where) {
    read_integer(j, out, where);
}
inline void read(const json& j, std::uint32_t& out, const std::string& where) {
    read_integer(j, out, where);
}
inline void read(const json& j, std::uint64_t& out, const std::string& where) {
    read_integer(j, out, where);
}
inline void read(const json& j, bool& out, const std::string& where) {
    if (!j.is_boolean()) fail(where, "expected true or false");
    out = j.get<bool>();
}
inline void read(const json& j, std::string& out, const std::string& where) {
    if (!j.is_string()) fail(where, "expected a string");
    out = j.get<std::string>();
}
inline void read(const json& j, Vec3f& out, const std::string& where) {
    if (!j.is_array() || j.size() != 3) fail(where, "expected [x, y, z]");
    read(j[0], out.x, where + "[0]"), read(j[1], out.y, where + "[1]"), read(j[2], out.z, where + "[2]");
}
template <class T>
void read(const json& j, std::vector<T>& out, const std::string& where) {
    if (!j.is_array()) fail(where, "expected an array");
    if (j.size() > 4096) fail(where, "more than 4096 entries");
    out.assign(j.size(), T{});
    for (std::size_t i = 0; i < j.size(); ++i) read(j[i], out[i], where + "[" + std::to_string(i) + "]");
}
// A struct: only keys it has; missing keys keep the value already in `out` (defaults or the base scene).
template <class T>
void read(const json& j, T& out, const std::string& where) {
    if (!j.is_object()) fail(where, "expected an object");
    std::set<std::string> known;
    members(out, [&](const char* key, auto& field) {
        known.insert(key);
        if (const auto it = j.find(key); it != j.end()) read(*it, field, where + "." + key);
    });
    for (const auto& [key, value] : j.items())
        if (!known.count(key)) fail(where + "." + key, "unknown key");
}

template <class T>
json write(const T& v);

inline json write(float v) {
    return v;
}
inline json write(int v) {
    return v;
}
inline json write(std::uint32_t v) {
    return v;
}
inline json write(std::uint64_t v) {
    return v;
}
inline json write(bool v) {
    return v;
}
inline json write(const std::string& v) {
    return v;
}
inline json write(const Vec3f& v) {
    return json::array({v.x, v.y, v.z});
}
template <class T>
json write(const std::vector<T>& v) {
    json a = json::array();
    for (const T& e : v) a.push_back(write(e));
    return a;
}
template <class T>
json write(const T& v) {
    json o = json::object();
    members(const_cast<T&>(v), [&](const char* key, auto& field) { o[key] = write(field); });
    return o;
}

}  // namespace rivulet::json_fields
