#pragma once
// Fixed-capacity, 64-byte aligned array of trivially copyable values. Capacity is chosen up front; the
// steady state never reallocates (DESIGN §3.2). Growth is explicit and rare (reserve).
#include <cstddef>
#include <cstring>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

namespace rivulet {

inline constexpr std::size_t kCacheLine = 64;

template <class T>
class AlignedArray {
    static_assert(std::is_trivially_copyable_v<T>);

  public:
    AlignedArray() = default;
    explicit AlignedArray(std::size_t capacity) { reserve(capacity); }
    AlignedArray(const AlignedArray&) = delete;
    AlignedArray& operator=(const AlignedArray&) = delete;
    AlignedArray(AlignedArray&& o) noexcept
        : data_(std::exchange(o.data_, nullptr)), capacity_(std::exchange(o.capacity_, 0)) {}
    AlignedArray& operator=(AlignedArray&& o) noexcept {
        std::swap(data_, o.data_);
        std::swap(capacity_, o.capacity_);
        return *this;
    }
    ~AlignedArray() { release(); }

    // Grows to at least `capacity`, keeping the first `keep` elements.
    void reserve(std::size_t capacity, std::size_t keep = 0) {
        if (capacity <= capacity_) return;
        T* fresh = static_cast<T*>(::operator new (capacity * sizeof(T), std::align_val_t{kCacheLine}));
        if (keep > 0) std::memcpy(fresh, data_, keep * sizeof(T));
        release();
        data_ = fresh;
        capacity_ = capacity;
    }

    std::size_t capacity() const { return capacity_; }
    T* data() { return data_; }
    const T* data() const { return data_; }
    T& operator[](std::size_t i) { return data_[i]; }
    const T& operator[](std::size_t i) const { return data_[i]; }
    std::span<T> span(std::size_t n) { return {data_, n}; }
    std::span<const T> span(std::size_t n) const { return {data_, n}; }

  private:
    void release() {
        if (data_) ::operator delete (data_, std::align_val_t{kCacheLine});
        data_ = nullptr;
        capacity_ = 0;
    }
    T* data_ = nullptr;
    std::size_t capacity_ = 0;
};

}  // namespace rivulet
