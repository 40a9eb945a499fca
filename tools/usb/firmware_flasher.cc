#include "tools/usb/firmware_flasher.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace hadynet::tools::usb {
namespace {

std::string hex32(std::uint64_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08llx", static_cast<unsigned long long>(v));
  return text;
}

constexpr const char* kRecover =
    "The ROM bootloader is in system memory and cannot be overwritten: to recover, hold BOOT0 high, reset the board "
    "(it enumerates as 0483:df11) and run hadynet flash again.";

// Where the flash stands when a write stopped at `address`.
std::string flash_state(std::uint32_t image_start, std::uint32_t address, std::uint32_t sectors_erased) {
  return " The flash holds " + std::to_string(sectors_erased) + " erased sector(s) and the image up to " +
         hex32(address) + " (from " + hex32(image_start) + "); the old firmware is gone. ";
}

}  // namespace

const char* phase_name(FlashPhase p) {
  switch (p) {
    case FlashPhase::kErase: return "erase";
    case FlashPhase::kWrite: return "write";
    case FlashPhase::kVerify: return "verify";
  }
  return "?";
}

std::vector<const DfuseSector*> FirmwareFlasher::plan(const FirmwareImage& image) const {
  const std::uint64_t start = image.address, end = start + image.bytes.size();
  const auto fits_nowhere = [&](const std::string& why) {
    const DfuseSector& first = layout_.sectors.front();
    const DfuseSector& last = layout_.sectors.back();
    return FlashError(3, "the image (" + hex32(start) + " .. " + hex32(end - 1) + ", " +
                             std::to_string(image.bytes.size()) + " bytes) " + why + " of the device's " +
                             layout_.name + " (" + hex32(first.address) + " .. " +
                             hex32(static_cast<std::uint64_t>(last.address) + last.size - 1) +
                             "). Nothing was written.");
  };
  if (image.bytes.empty()) throw FlashError(3, "the image is empty. Nothing was written.");
  // Checked here, before anything is erased: wTransferSize 0 would never
  // advance, and DfuSe block numbers (from 2) are 16 bits.
  if (transfer_size_ == 0) throw FlashError(7, "the device's wTransferSize is 0. Nothing was written.");
  if ((image.bytes.size() + transfer_size_ - 1) / transfer_size_ > 0xFFFF - 1) {  // blocks 2 .. 0xFFFF
    throw FlashError(3, "the image needs more than 65534 blocks of wTransferSize (" + std::to_string(transfer_size_) +
                            " bytes). Nothing was written.");
  }
  std::vector<const DfuseSector*> sectors;
  for (std::uint64_t at = start; at < end;) {
    const DfuseSector* s = layout_.sector_at(static_cast<std::uint32_t>(at));
    if (s == nullptr) throw fits_nowhere(at == start ? "starts outside" : "does not fit inside");
    if (!s->erasable || !s->writable) {
      throw fits_nowhere("covers the sector at " + hex32(s->address) + ", which is not erasable and writable, ");
    }
    sectors.push_back(s);
    at = static_cast<std::uint64_t>(s->address) + s->size;
  }
  return sectors;
}

FlashResult FirmwareFlasher::write_and_verify(const FirmwareImage& image) {
  const std::vector<const DfuseSector*> sectors = plan(image);  // throws before anything is touched
  FlashResult result;
  std::uint32_t at = image.address;  // for the error messages: how far the write got
  try {
    client_.ensure_idle();
    std::uint64_t erase_total = 0;
    for (const DfuseSector* s : sectors) erase_total += s->size;
    std::uint64_t erased = 0;
    progress_({FlashPhase::kErase, 0, erase_total});
    for (const DfuseSector* s : sectors) {
      client_.dfuse_erase_sector(s->address);
      ++result.sectors_erased;
      erased += s->size;
      progress_({FlashPhase::kErase, erased, erase_total});
    }

    client_.dfuse_set_address(image.address);
    const std::size_t total = image.bytes.size();
    progress_({FlashPhase::kWrite, 0, total});
    for (std::size_t offset = 0, block = 2; offset < total; offset += transfer_size_, ++block) {
      const std::size_t n = std::min<std::size_t>(transfer_size_, total - offset);
      at = image.address + static_cast<std::uint32_t>(offset);
      client_.download(static_cast<std::uint16_t>(block), std::span(image.bytes).subspan(offset, n));
      result.bytes_written += n;
      progress_({FlashPhase::kWrite, result.bytes_written, total});
    }
    at = image.address + static_cast<std::uint32_t>(total);

    // Read back: address pointer, ABORT to dfuIDLE, UPLOAD from block 2.
    client_.dfuse_set_address(image.address);
    client_.abort();
    std::vector<std::uint8_t> block_bytes(transfer_size_);
    progress_({FlashPhase::kVerify, 0, total});
    for (std::size_t offset = 0, block = 2; offset < total; offset += transfer_size_, ++block) {
      const std::size_t want = std::min<std::size_t>(transfer_size_, total - offset);
      const std::size_t got = client_.upload(static_cast<std::uint16_t>(block), std::span(block_bytes).first(want));
      if (got != want) {
        throw FlashError(6, "verify: the device returned " + std::to_string(got) + " bytes for the " +
                                std::to_string(want) + " at " + hex32(image.address + offset) + ". " + kRecover);
      }
      for (std::size_t i = 0; i < want; ++i) {
        if (block_bytes[i] != image.bytes[offset + i]) {
          char text[96];
          std::snprintf(text, sizeof text, "verify failed at %s: wrote 0x%02x, read back 0x%02x.",
                        hex32(image.address + offset + i).c_str(), image.bytes[offset + i], block_bytes[i]);
          throw FlashError(6, std::string(text) +
                                  " The flash does not hold the image (a worn or protected sector?); do not run "
                                  "this firmware. Flash it again; if the same address fails, the MCU's flash is "
                                  "faulty. " + kRecover);
        }
      }
      result.bytes_verified += want;
      progress_({FlashPhase::kVerify, result.bytes_verified, total});
    }
    client_.abort();
    return result;
  } catch (const FlashError&) {
    throw;
  } catch (const UsbTransferError& e) {
    if (e.kind() == UsbTransferError::Kind::kGone) {
      throw FlashError(4, "the device vanished (" + std::string(e.what()) + ")." +
                              flash_state(image.address, at, result.sectors_erased) + kRecover);
    }
    throw FlashError(7, std::string("USB transfer failed: ") + e.what() + "." +
                            flash_state(image.address, at, result.sectors_erased) + kRecover);
  } catch (const DfuError& e) {
    throw FlashError(5, std::string(e.what()) + "." + flash_state(image.address, at, result.sectors_erased) + kRecover);
  }
}

void FirmwareFlasher::leave(std::uint32_t address) {
  try {
    client_.ensure_idle();
    client_.dfuse_set_address(address);
    client_.finish_download();
  } catch (const UsbTransferError& e) {
    throw FlashError(7, std::string("the image is written and verified, but leaving the bootloader failed (") +
                            e.what() + "): reset the board to start it.");
  } catch (const DfuError& e) {
    throw FlashError(5, std::string("the image is written and verified, but leaving the bootloader failed (") +
                            e.what() + "): reset the board to start it.");
  }
}

FlashResult FirmwareFlasher::flash(const FirmwareImage& image) {
  const FlashResult result = write_and_verify(image);
  leave(image.address);
  return result;
}

}  // namespace hadynet::tools::usb
