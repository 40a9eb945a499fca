#include "cli/pb_map_plot.h"

#include <cstdio>
#include <map>

#include "cli/gnuplot.h"
#include "trainer/recognition.h"

namespace hadynet::cli {

namespace {

std::string point(const Eigen::VectorXd& p) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g %.6g", p(0), p(1));
  return buf;
}

}  // namespace

std::string plot_pb_map(const trainer::HadynetModel& model, const std::vector<MarkedPb>& marked,
                        const std::vector<Eigen::VectorXf>& trajectory, const std::string& title,
                        const std::string& png) {
  const Eigen::MatrixXd table = model.params.pb.cast<double>();
  const trainer::Pca pca = trainer::fit_pca(table, std::min<int>(2, static_cast<int>(table.cols())));
  const auto project = [&](const Eigen::VectorXd& p) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(2);
    q.head(pca.axes.cols()) = pca.project(p);
    return q;
  };
  // One data block per object so each gets its own colour and key entry.
  std::map<std::string, std::vector<int>> rows_of_object;
  for (std::size_t k = 0; k < model.states.size(); ++k)
    rows_of_object[model.states[k].object.empty() ? "(no object)" : model.states[k].object]
        .push_back(static_cast<int>(k));
  std::string s;
  int block = 0;
  std::string plots;
  for (const auto& [object, rows] : rows_of_object) {
    s += "$obj" + std::to_string(block) + " << EOD\n";
    for (int k : rows) s += point(project(table.row(k).transpose())) + "\n";
    s += "EOD\n";
    plots += std::string(plots.empty() ? "" : ", ") + "$obj" + std::to_string(block) +
             " using 1:2 with points pt 7 ps 1.6 title " + gnuplot_quote(object);
    ++block;
  }
  if (!trajectory.empty()) {
    s += "$traj << EOD\n";
    for (const auto& p : trajectory) s += point(project(p.cast<double>())) + "\n";
    s += "EOD\n";
    plots += ", $traj using 1:2 with linespoints lw 1.5 pt 6 ps 0.5 lc rgb '#444444' title 'online PB'";
  }
  if (!marked.empty()) {
    s += "$new << EOD\n";
    for (const auto& m : marked) s += point(project(m.pb.cast<double>())) + " \"" + m.label + "\"\n";  // data: double quotes
    s += "EOD\n";
    plots += ", $new using 1:2 with points pt 3 ps 2.5 lw 2 lc rgb 'black' title 'adapted PB'";
    plots += ", $new using 1:2:3 with labels offset 1,1 left font 'sans,8' notitle";
  }
  char axes[160];
  std::snprintf(axes, sizeof axes, "set xlabel 'PC1 (%.0f%% of PB variance)'\nset ylabel 'PC2 (%.0f%%)'\n",
                100.0 * pca.explained(0), pca.explained.size() > 1 ? 100.0 * pca.explained(1) : 0.0);
  s += "set terminal pngcairo size 900,700 font 'sans,10' noenhanced\n";
  s += "set output " + gnuplot_quote(png) + "\n";
  s += "set title " + gnuplot_quote(title) + "\nset grid\nset key outside right top\n";
  s += axes;
  s += "plot " + plots + "\n";
  return run_gnuplot(s, png);
}

}  // namespace hadynet::cli
