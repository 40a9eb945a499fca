// The loadcell readings the 5 Hz loop took last (newtons), for whoever
// reports them (the link, the test console).
#ifndef HADYNET_FIRMWARE_APP_LOADCELL_SNAPSHOT_H_
#define HADYNET_FIRMWARE_APP_LOADCELL_SNAPSHOT_H_

#include <cstdint>

#include "boards/board.h"

namespace hadynet::app {

struct LoadcellSnapshot {
  bool valid = false;                        // false: no board loadcells, or no scan yet
  std::uint32_t period = 0;                  // control period it was taken in
  float newtons[board::kLoadcells] = {};
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_LOADCELL_SNAPSHOT_H_
