// stm32f405's model flash (boards/board.h, model_flash()): the embedded
// flash through its controller driver, the two model slots of
// firmware/flash/stm32f405_flash_layout.h (sectors 8..9 and 10..11), and the
// flash as mapped at 0x08000000, from which the runtime reads the booted
// model in place (docs/model-update.md). The USB port's DFU interface writes
// the slots through the same driver.
#include <algorithm>
#include <cstdint>
#include <span>

#include "board_config.h"
#include "boards/board.h"
#include "boards/stm32f405/flash_controller.h"
#include "firmware/flash/stm32f405_flash_layout.h"

namespace hadynet::board {
namespace {

namespace layout = flash::stm32f405;

static_assert(config::kFLASHOrigin + config::kFLASHBytes <=
                  layout::kFlashBase + std::min(layout::kModelSlotAOffset, layout::kModelSlotBOffset),
              "the firmware's flash region (board.cmake) overlaps a model slot");

stm32::FlashController g_flash(stm32::flash_interface_registers(), stm32::flash_memory_window(),
                               config::kCoreClockHz);

}  // namespace

const ModelFlash* model_flash() noexcept {
  static const ModelFlash kModelFlash{
      g_flash,
      {layout::kModelSlotAOffset, layout::kModelSlotSize},
      {layout::kModelSlotBOffset, layout::kModelSlotSize},
      std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(layout::kFlashBase), layout::kFlashSize)};
  return &kModelFlash;
}

}  // namespace hadynet::board
