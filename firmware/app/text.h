// A fixed-capacity text buffer for the firmware's human-readable output (the
// benchmark report, the USB strings the device composes: its configuration
// string, the DFU status text): integers in decimal and hex, no stdio
// (newlib's printf family may allocate), nothing allocated. Always
// NUL-terminated (c_str()). Text that does not fit is cut off and marked by
// truncated().
#ifndef HADYNET_FIRMWARE_APP_TEXT_H_
#define HADYNET_FIRMWARE_APP_TEXT_H_

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>

namespace hadynet::app {

template <std::size_t kCapacity>
class Text {
 public:
  Text& operator<<(std::string_view s) noexcept {
    for (const char c : s) put(c);
    return *this;
  }
  Text& operator<<(char c) noexcept {
    put(c);
    return *this;
  }
  // Any integer except char (above), in decimal.
  template <std::integral T>
    requires(!std::is_same_v<T, char> && !std::is_same_v<T, bool>)
  Text& operator<<(T v) noexcept {
    if constexpr (std::is_signed_v<T>) {
      if (v < 0) {
        put('-');
        return decimal(~static_cast<std::uint64_t>(static_cast<std::int64_t>(v)) + 1);  // |INT64_MIN| too
      }
    }
    return decimal(static_cast<std::uint64_t>(v));
  }
  // Lowercase hex of v, exactly `digits` digits.
  Text& hex(std::uint64_t v, int digits = 16) noexcept {
    for (int i = digits - 1; i >= 0; --i) put("0123456789abcdef"[(v >> (4 * i)) & 0xFu]);
    return *this;
  }

  void clear() noexcept {
    size_ = 0;
    data_[0] = 0;
    truncated_ = false;
  }
  std::span<const std::uint8_t> bytes() const noexcept { return {data_, size_}; }
  const char* c_str() const noexcept { return reinterpret_cast<const char*>(data_); }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  std::string_view view() const noexcept { return {reinterpret_cast<const char*>(data_), size_}; }
  bool truncated() const noexcept { return truncated_; }

 private:
  Text& decimal(std::uint64_t v) noexcept {
    char digits[20];
    int n = 0;
    do {
      digits[n++] = static_cast<char>('0' + v % 10);
      v /= 10;
    } while (v != 0);
    while (n > 0) put(digits[--n]);
    return *this;
  }
  void put(char c) noexcept {
    if (size_ < kCapacity) {
      data_[size_++] = static_cast<std::uint8_t>(c);
      data_[size_] = 0;
    } else {
      truncated_ = true;
    }
  }
  std::uint8_t data_[kCapacity + 1] = {};  // and the NUL
  std::size_t size_ = 0;
  bool truncated_ = false;
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_TEXT_H_
