// The PB map: the trained PBs projected on their first two principal axes,
// coloured by object, with adapted PBs (and optionally an online trajectory)
// marked on top. Written as a PNG by gnuplot.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"

namespace hadynet::cli {

struct MarkedPb {
  std::string label;   // drawn next to the point
  Eigen::VectorXf pb;
};

// Returns "" on success or a message (see run_gnuplot).
std::string plot_pb_map(const trainer::HadynetModel& model, const std::vector<MarkedPb>& marked,
                        const std::vector<Eigen::VectorXf>& trajectory, const std::string& title,
                        const std::string& png);

}  // namespace hadynet::cli
