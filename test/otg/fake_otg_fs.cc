#include "test/otg/fake_otg_fs.h"

#include <algorithm>

namespace hadynet::board::stm32::testing {

namespace {

constexpr std::uint32_t kEpctlActions = otg::kEpctlClearNak | otg::kEpctlSetNak | otg::kEpctlSetData0 |
                                        (1u << 29) /* SODDFRM */ | otg::kEpctlDisable | otg::kEpctlEnable;
constexpr std::uint32_t kDctlActions =
    (1u << 7) | otg::kDctlClearGlobalInNak | otg::kDctlSetGlobalOutNak | otg::kDctlClearGlobalOutNak;

std::uint32_t word_of(std::span<const std::uint8_t> bytes, std::size_t i) {
  std::uint32_t w = 0;
  for (std::size_t k = 0; k < 4 && i + k < bytes.size(); ++k) w |= static_cast<std::uint32_t>(bytes[i + k]) << (8 * k);
  return w;
}

}  // namespace

FakeOtgFs::FakeOtgFs() {
  // Reset values (RM0090) of the registers the driver reads back.
  set_reg(otg::kGusbcfg, 0x00000A00);
  set_reg(otg::kDcfg, 0x02200000);
  set_reg(otg::kGrxfsiz, 0x00000200);
  set_reg(otg::kDieptxf0, 0x00000200);
  set_reg(otg::diepctl(0), otg::kEpctlActive);
  set_reg(otg::doepctl(0), otg::kEpctlActive);
}

std::uint32_t FakeOtgFs::rx_status(int ep, std::uint32_t packet_status, std::uint32_t bytes) {
  return static_cast<std::uint32_t>(ep) | (bytes << otg::kRxStatusByteCount) |
         (packet_status << otg::kRxStatusPacketStatus);
}

std::uint32_t FakeOtgFs::tx_fifo_depth(int n) const {
  return reg(n == 0 ? otg::kDieptxf0 : otg::dieptxf(n)) >> otg::kTxFifoDepth;
}

std::uint32_t FakeOtgFs::diepint(int n) const {
  return reg(otg::diepint(n)) | (tx_[static_cast<std::size_t>(n)].empty() ? otg::kInTxFifoEmpty : 0);
}

std::uint32_t FakeOtgFs::daint() const {
  std::uint32_t bits = 0;
  for (int n = 0; n < otg::kEndpoints; ++n) {
    const std::uint32_t in_mask =
        reg(otg::kDiepmsk) | (((reg(otg::kDiepempmsk) >> n) & 1) != 0 ? otg::kInTxFifoEmpty : 0);
    if ((diepint(n) & in_mask) != 0) bits |= otg::daint_in(n);
    if ((reg(otg::doepint(n)) & reg(otg::kDoepmsk)) != 0) bits |= otg::daint_out(n);
  }
  return bits;
}

std::uint32_t FakeOtgFs::gintsts() const {
  const std::uint32_t endpoints = daint() & reg(otg::kDaintmsk);
  return latched_ | (rx_status_.empty() ? 0 : otg::kGintRxFifoNonEmpty) |
         ((endpoints & 0xFFFF) != 0 ? otg::kGintInEndpoint : 0) | ((endpoints >> 16) != 0 ? otg::kGintOutEndpoint : 0) |
         (global_out_nak_ ? otg::kGintGlobalOutNakEffective : 0);
}

std::uint32_t FakeOtgFs::read(std::uint32_t offset) {
  if (offset == otg::kGintsts) return gintsts();
  if (offset == otg::kGrstctl) return reg(offset) | otg::kGrstctlAhbIdle;
  if (offset == otg::kDaint) return daint();
  if (offset == otg::kGrxstsr) return rx_status_.empty() ? 0 : rx_status_.front();
  if (offset == otg::kGrxstsp) {
    if (rx_status_.empty()) return 0;
    const std::uint32_t status = rx_status_.front();
    rx_status_.pop_front();
    const int n = static_cast<int>(status & otg::kRxStatusEndpointMask);
    const std::uint32_t kind = (status & otg::kRxStatusPacketStatusMask) >> otg::kRxStatusPacketStatus;
    if (kind == otg::kRxSetupComplete) regs_[otg::doepint(0) / 4] |= otg::kOutSetupDone;
    if (kind == otg::kRxOutComplete) regs_[otg::doepint(n) / 4] |= otg::kOutTransferComplete;
    return status;
  }
  for (int n = 0; n < otg::kEndpoints; ++n) {
    if (offset == otg::diepint(n)) return diepint(n);
    if (offset == otg::dtxfsts(n)) {
      return tx_fifo_depth(n) - static_cast<std::uint32_t>(tx_[static_cast<std::size_t>(n)].size());
    }
  }
  return reg(offset);
}

void FakeOtgFs::write_endpoint_control(std::uint32_t offset, std::uint32_t value, bool in, int n) {
  const std::uint32_t old = reg(offset);
  bool enabled = (old & otg::kEpctlEnable) != 0 || (value & otg::kEpctlEnable) != 0;
  if ((value & otg::kEpctlDisable) != 0 && (old & otg::kEpctlEnable) != 0) {
    enabled = false;
    regs_[(in ? otg::diepint(n) : otg::doepint(n)) / 4] |= in ? otg::kInDisabled : otg::kOutDisabled;
  }
  if ((value & otg::kEpctlSetData0) != 0) (in ? in_data0_ : out_data0_)[static_cast<std::size_t>(n)] = true;
  bool nak = (old & otg::kEpctlNakStatus) != 0;
  if ((value & otg::kEpctlSetNak) != 0) nak = true;
  if ((value & otg::kEpctlClearNak) != 0) nak = false;
  std::uint32_t stored = (value & ~(kEpctlActions | otg::kEpctlNakStatus)) | (enabled ? otg::kEpctlEnable : 0) |
                         (nak ? otg::kEpctlNakStatus : 0);
  if (n == 0) stored |= otg::kEpctlActive;  // EP0 is always active
  set_reg(offset, stored);
}

void FakeOtgFs::write(std::uint32_t offset, std::uint32_t value) {
  if (offset == otg::kGintsts) {
    latched_ &= ~value;
    return;
  }
  if (offset == otg::kGrstctl) {
    if ((value & otg::kGrstctlCoreReset) != 0) ++core_resets_;
    if ((value & otg::kGrstctlRxFlush) != 0) {
      ++rx_flushes_;
      rx_status_.clear();
      rx_data_.clear();
    }
    if ((value & otg::kGrstctlTxFlush) != 0) {
      ++tx_flushes_;
      const std::uint32_t which = (value >> otg::kGrstctlTxFifoNumber) & 0x1F;
      for (int n = 0; n < otg::kEndpoints; ++n) {
        if (which == otg::kGrstctlTxFlushAll || which == static_cast<std::uint32_t>(n)) {
          tx_[static_cast<std::size_t>(n)].clear();
        }
      }
    }
    set_reg(offset, value & ~(otg::kGrstctlCoreReset | otg::kGrstctlRxFlush | otg::kGrstctlTxFlush));
    return;
  }
  if (offset == otg::kDctl) {
    if ((value & otg::kDctlSetGlobalOutNak) != 0) global_out_nak_ = true;
    if ((value & otg::kDctlClearGlobalOutNak) != 0) global_out_nak_ = false;
    set_reg(offset, value & ~kDctlActions);
    return;
  }
  if (offset == otg::kDaint || offset == otg::kGrxstsr || offset == otg::kGrxstsp) return;  // read only
  for (int n = 0; n < otg::kEndpoints; ++n) {
    if (offset == otg::diepint(n) || offset == otg::doepint(n)) {
      regs_[offset / 4] &= ~value;
      return;
    }
    if (offset == otg::dtxfsts(n)) return;
    if (offset == otg::diepctl(n)) return write_endpoint_control(offset, value, true, n);
    if (offset == otg::doepctl(n)) return write_endpoint_control(offset, value, false, n);
  }
  set_reg(offset, value);
}

void FakeOtgFs::write_fifo_word(int fifo, std::uint32_t word) {
  auto& q = tx_[static_cast<std::size_t>(fifo)];
  q.push_back(word);
  pushed_[static_cast<std::size_t>(fifo)].push_back(word);
  if (q.size() > tx_fifo_depth(fifo)) ++fifo_overruns_;
}

std::uint32_t FakeOtgFs::read_fifo_word() {
  if (rx_data_.empty()) {
    ++fifo_underruns_;
    return 0xDEADBEEF;
  }
  const std::uint32_t w = rx_data_.front();
  rx_data_.pop_front();
  return w;
}

void FakeOtgFs::queue_rx(std::uint32_t status, std::span<const std::uint32_t> words) {
  rx_status_.push_back(status);
  for (const std::uint32_t w : words) rx_data_.push_back(w);
}

void FakeOtgFs::setup(std::span<const std::uint8_t, 8> packet) {
  // The core clears both EP0 STALL bits when a SETUP arrives.
  regs_[otg::diepctl(0) / 4] &= ~otg::kEpctlStall;
  regs_[otg::doepctl(0) / 4] &= ~otg::kEpctlStall;
  const std::uint32_t words[2] = {word_of(packet, 0), word_of(packet, 4)};
  queue_rx(rx_status(0, otg::kRxSetupData, 8), words);
  queue_rx(rx_status(0, otg::kRxSetupComplete, 0));
}

bool FakeOtgFs::out_packet(int n, std::span<const std::uint8_t> packet) {
  const std::uint32_t control = reg(otg::doepctl(n));
  if ((control & otg::kEpctlEnable) == 0 || (control & otg::kEpctlStall) != 0) return false;
  const std::uint32_t max_packet = n == 0 ? 64 : (control & otg::kEpctlMaxPacketMask);
  std::vector<std::uint32_t> words;
  for (std::size_t i = 0; i < packet.size(); i += 4) words.push_back(word_of(packet, i));
  const auto bytes = static_cast<std::uint32_t>(packet.size());
  queue_rx(rx_status(n, otg::kRxOutData, bytes), words);
  const std::uint32_t tsiz = reg(otg::doeptsiz(n));
  std::uint32_t packets = (tsiz >> otg::kTsizPacketCount) & otg::kTsizPacketCountMax;
  std::uint32_t size = tsiz & otg::kTsizSizeMask;
  packets = packets > 0 ? packets - 1 : 0;
  size = size > bytes ? size - bytes : 0;
  set_reg(otg::doeptsiz(n), (tsiz & otg::kTsizSetupCountMask) | (packets << otg::kTsizPacketCount) | size);
  if (bytes < max_packet || packets == 0) {
    set_reg(otg::doepctl(n), control & ~otg::kEpctlEnable);
    queue_rx(rx_status(n, otg::kRxOutComplete, 0));
  }
  return true;
}

std::optional<std::vector<std::uint8_t>> FakeOtgFs::in_token(int n) {
  const std::uint32_t control = reg(otg::diepctl(n));
  if ((control & otg::kEpctlEnable) == 0 || (control & otg::kEpctlStall) != 0) return std::nullopt;
  const std::uint32_t max_packet =
      n == 0 ? (64u >> (control & otg::kEpctl0MaxPacketMask)) : (control & otg::kEpctlMaxPacketMask);
  const std::uint32_t tsiz = reg(otg::dieptsiz(n));
  const std::uint32_t size_mask = n == 0 ? otg::kTsiz0SizeMask : otg::kTsizSizeMask;
  const std::uint32_t count_mask = n == 0 ? 3u : otg::kTsizPacketCountMax;
  std::uint32_t size = tsiz & size_mask;
  std::uint32_t packets = (tsiz >> otg::kTsizPacketCount) & count_mask;
  if (packets == 0) return std::nullopt;
  const std::uint32_t bytes = std::min(max_packet, size);
  const std::size_t words = (bytes + 3) / 4;
  auto& q = tx_[static_cast<std::size_t>(n)];
  if (q.size() < words) return std::nullopt;  // not pushed yet: NAK
  std::vector<std::uint8_t> packet;
  for (std::size_t w = 0; w < words; ++w) {
    const std::uint32_t word = q.front();
    q.pop_front();
    for (std::uint32_t k = 0; k < 4 && packet.size() < bytes; ++k)
      packet.push_back(static_cast<std::uint8_t>(word >> (8 * k)));
  }
  size -= bytes;
  --packets;
  set_reg(otg::dieptsiz(n), (packets << otg::kTsizPacketCount) | size);
  if (packets == 0) {
    set_reg(otg::diepctl(n), control & ~otg::kEpctlEnable);
    regs_[otg::diepint(n) / 4] |= otg::kInTransferComplete;
  }
  return packet;
}

}  // namespace hadynet::board::stm32::testing
