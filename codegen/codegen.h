// HADYNET codegen (DESIGN.md §3, §6; docs/codegen.md): a trained model file
// -> one allocation-free C++ header holding one struct of static constexpr
// constants and arrays that satisfies hadynet::firmware::GeneratedModel
// (firmware/core/model_contract.h, the specification of every member).
//
// Everything here is pure: the same model, hash and options give the same
// text, byte for byte. An unsupported or malformed model is rejected with
// UnsupportedModel before any text exists, so a caller that writes only
// after generate() returned never leaves a partial or stale file.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "firmware/core/model_contract.h"
#include "trainer/hadynet_model.h"

namespace hadynet::codegen {

using Numeric = hadynet::firmware::Numeric;

using hadynet::firmware::numeric_name;  // "q15" or "f32"

// The model (or the options) cannot be generated; what() names the problem.
class UnsupportedModel : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Grasp stabiliser constants written into the header (seed paper III-F,
// DESIGN.md §4).
struct ControlOptions {
  int horizon = 8;                                     // N_control, 1 .. N_train
  int epochs = 3;                                      // N_epoch >= 1
  std::vector<double> alphas = {1.0, 0.5, 0.25, 0.125};  // step sizes (standardised units), > 0
  std::optional<int> truncation;                       // K >= 1; none: = horizon (full BPTT)
  double beta = 3.0;                                   // force weight where est < ref
  double w2 = 1.0;                                     // angle weight
  double w3 = 1.0;                                     // length weight
  // Loss classes of y channels, by channel group (trainer::channel_group:
  // "fc3" -> "fc"). Each group must name at least one y channel; a group in
  // two classes is an error. Other channels are not in the loss.
  // Units the loss is computed in. Physical (default, the seed paper's raw
  // sensor values): channel i's weight is multiplied by std_i^2, so that the
  // standardised error gives the physical one; the weights are then scaled
  // so that the largest is 1 (only the direction of dL/du and the order of
  // losses matter). Standardised: the class weights as given (<= 7.99).
  bool physical_units = true;
  // u channels the stabiliser may change (names); the others stay at "no
  // change". Empty: all. None: the model's robot profile (its
  // control_commands; all when it names none).
  std::optional<std::vector<std::string>> commands;
  // The groups of each loss class. None: the model's robot profile
  // (datalog/robot_profile.h: the hand's logs say f, fc / th / l); a model
  // without a profile has no loss classes unless they are given.
  std::optional<std::vector<std::string>> force_groups;
  std::optional<std::vector<std::string>> angle_groups;
  std::optional<std::vector<std::string>> length_groups;
};

struct CodegenOptions {
  Numeric numeric = Numeric::kQ15;
  std::string ns;         // C++ namespace; empty: "hadynet::model_q15" / "hadynet::model_f32"
  double headroom = 1.5;  // measured activation ranges are multiplied by it (>= 1)
  ControlOptions control;
};

// The namespace the header uses (options.ns or the default).
std::string namespace_of(const CodegenOptions& options);

// The file the header is written to: "hadynet_model_q15.h" / "hadynet_model_f32.h".
std::string header_file_name(Numeric numeric);

// The format rule (docs/codegen.md): for a largest magnitude m >= 0,
//   F = 15 - ceil(log2 m), clamped to [0, 15], then lowered while
//   round(m 2^F) > 32767 (rounding half away from zero, as real_to_fixed),
// so that m and -m fit an int16 Q(F); m == 0 gives 15. Throws
// UnsupportedModel naming `what` when m is negative or not finite, or does
// not fit even Q0 (round(m) > 32767).
int frac_bits_for(double max_abs, const std::string& what = "value");

// real * 2^frac rounded half away from zero: firmware/core/fixed_point.h's
// real_to_fixed<int64_t, frac> (0 <= frac <= 62).
std::int64_t to_fixed(double real, int frac);

// One chosen format and where it came from.
struct FormatChoice {
  int frac = 0;      // frac bits of Q(frac)
  double m = 0;      // largest magnitude the format must hold (0 for fixed formats)
  std::string from;  // e.g. "1.5 x |h| 3.21" or "fixed: activation input Q3.12"
};

// Every kFrac* of the contract (q15; an f32 header writes 0 for all).
struct Formats {
  FormatChoice in, h, c, y, gate, enc_w, lstm_w, lstm_acc, dec_w, whiten, z, loss_w;
};

// Checks the model and options (throws UnsupportedModel) and chooses the
// formats from model.ranges, the weights, the PB table, the detection
// statistics and the control constants.
Formats choose_formats(const trainer::HadynetModel& model, const CodegenOptions& options);

// Detection whitening: for the regularised inverse covariance S (symmetric
// positive definite), S = V diag(lambda) V^T and W = diag(sqrt(lambda)) V^T,
// so W^T W = S and d^2 = |W (e - mu)|^2. Eigenvalues ascending; each
// eigenvector's largest-magnitude entry is made positive (deterministic
// signs). Throws UnsupportedModel if S is not square, not symmetric (relative
// 1e-9) or not positive definite.
Eigen::MatrixXd whitening_matrix(const Eigen::MatrixXd& inverse);

// Where the model came from, stamped into the header.
struct ModelIdentity {
  std::string file_name;  // shown in the header comment (a base name keeps it build-dir independent)
  std::uint64_t hash = 0; // datalog::fnv1a64 of the model file's bytes (kModelHash)
};

struct GeneratedHeader {
  std::string file_name;  // header_file_name(options.numeric)
  std::string text;       // the whole header
  Formats formats;        // as chosen (all frac 0 in an f32 header's constants)
};

// The header for `model` (throws UnsupportedModel before producing anything).
GeneratedHeader generate(const trainer::HadynetModel& model, const ModelIdentity& identity,
                         const CodegenOptions& options);

// A model file read for codegen: the model and the identity of its bytes.
struct LoadedModel {
  trainer::HadynetModel model;
  ModelIdentity identity;
};
// Reads the file once, hashes those bytes and parses them (trainer/model_file.h).
// Throws trainer::ModelFileError naming the path.
LoadedModel load_model_file(const std::string& path);

// Writes header.text to dir/header.file_name atomically (a temporary file in
// dir, then rename); creates dir if needed. An existing file with the same
// text is left untouched (so nothing that includes it rebuilds). Returns the
// path and whether the file changed. Throws std::runtime_error naming the path.
struct WriteResult {
  std::string path;
  bool changed = false;
};
WriteResult write_header(const std::string& dir, const GeneratedHeader& header);

}  // namespace hadynet::codegen
