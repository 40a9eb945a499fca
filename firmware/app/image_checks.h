// The compile-time agreement of a firmware image's model with its board
// (included by the image's main file, which is built for one board, so
// board_config.h is the board's): the model's board channels are the
// board's loadcells, and the model was trained at the board's control period.
#ifndef HADYNET_FIRMWARE_APP_IMAGE_CHECKS_H_
#define HADYNET_FIRMWARE_APP_IMAGE_CHECKS_H_

#include "board_config.h"
#include "boards/board.h"
#include "firmware/app/channel_layout.h"
#include "firmware/core/model_contract.h"

namespace hadynet::app {

template <firmware::GeneratedModel M>
constexpr bool model_fits_board() noexcept {
  static_assert(ChannelLayout<M>::kLoadcells == board::config::kLoadcells,
                "the model's board channels (<kBoardGroup><k>) and the board's loadcells "
                "(BOARD_LOADCELLS in its board.cmake) differ in number");
  static_assert(M::kPeriodUs * board::kPeriodHz == 1000000u,
                "the model was trained at another control period (kPeriodUs, the logs' dt_s) "
                "than the board's loop runs at (board::kPeriodHz)");
  return true;
}

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_IMAGE_CHECKS_H_
