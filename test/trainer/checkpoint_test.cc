// Training checkpoints (trainer/checkpoint.h): exact round trip of the
// model, the Adam state, the history and the options; a checkpoint is not a
// plain model file; resuming continues bit for bit as if never stopped.
// No tolerances: checkpoints store the float tensors and Adam moments as
// F32 and the losses as shortest round-trip JSON numbers, and training is
// deterministic, so every comparison is exact (bits).
#include "test_batches.h"
#include "trainer/checkpoint.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "synthetic_logs.h"
#include "trainer/model_file.h"
#include "trainer/safetensors.h"

namespace hadynet::trainer::testing {
namespace {

namespace st = safetensors;

struct CheckpointData {
  FeatureLayout layout = spring_layout();
  std::vector<LogSequence> seqs = {spring_sequence(kSoftStiffness, 40, 21, "soft"),
                                   spring_sequence(kStiffStiffness, 40, 22, "stiff")};
  Normalization norm = fit_normalization(seqs, layout);
  WindowDataset data{seqs, {0, 1}, layout, norm, 4};
  WindowDataset::Split split = data.split_tail(0.2);
  HadynetModel fresh = new_model(layout, norm, {{"soft", ""}, {"stiff", ""}}, 2, 8, 4, 31);

  TrainOptions options(int epochs, bool variable_pb = true) const {
    TrainOptions o;
    o.epochs = epochs;
    o.batch = 16;
    o.lr = 1e-2;
    o.seed = 5;
    o.variable_pb = variable_pb;
    return o;
  }
  void run(HadynetModel& model, TrainingState& state, const TrainOptions& o,
           std::vector<int>* epochs_seen = nullptr) const {
    train(model, state, data, split.train, split.held_out, o, [&](const EpochStats& e) {
      if (epochs_seen != nullptr) epochs_seen->push_back(e.epoch);
    });
  }
};

void expect_same_adam(const Adam<float>::State& got, const Adam<float>::State& want) {
  // A tensor never updated may be absent or empty: compare by content.
  const std::size_t n = std::max(got.m.size(), want.m.size());
  for (std::size_t i = 0; i < n; ++i) {
    const Vector<float> gm = i < got.m.size() ? got.m[i] : Vector<float>();
    const Vector<float> wm = i < want.m.size() ? want.m[i] : Vector<float>();
    const Vector<float> gv = i < got.v.size() ? got.v[i] : Vector<float>();
    const Vector<float> wv = i < want.v.size() ? want.v[i] : Vector<float>();
    const long gt = i < got.t.size() ? got.t[i] : 0;
    const long wt = i < want.t.size() ? want.t[i] : 0;
    EXPECT_EQ(gm, wm) << "m of tensor " << i;
    EXPECT_EQ(gv, wv) << "v of tensor " << i;
    EXPECT_EQ(gt, wt) << "t of tensor " << i;
  }
}

// Exact equality of doubles, NaN equal to NaN.
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Checkpoint, RoundTripIsExact) {
  const CheckpointData s;
  Checkpoint c{s.fresh, {}, s.options(2)};
  c.model.hyper_parameters = {{"lr", "0.01"}};
  s.run(c.model, c.state, c.options);
  ASSERT_EQ(c.state.history.size(), 2u);
  c.state.history[0].held_out_loss = std::numeric_limits<double>::quiet_NaN();  // "no held-out data"
  c.options.seed = 0xfedcba9876543210ULL;  // needs all 64 bits

  TempDir dir;
  const std::string path = (dir.path() / "ckpt.safetensors").string();
  save_checkpoint(path, c);
  const Checkpoint r = load_checkpoint(path);

  EXPECT_TRUE(bit_identical(r.model.params, c.model.params));
  EXPECT_EQ(r.model.bn_batches_tracked, c.model.bn_batches_tracked);
  EXPECT_EQ(r.model.layout, c.model.layout);
  EXPECT_EQ(r.model.hyper_parameters, c.model.hyper_parameters);
  EXPECT_EQ(r.state.epochs_done, 2);
  expect_same_adam(r.state.adam, c.state.adam);
  ASSERT_EQ(r.state.history.size(), 2u);
  for (std::size_t e = 0; e < 2; ++e) {
    EXPECT_EQ(r.state.history[e].epoch, c.state.history[e].epoch);
    EXPECT_TRUE(same(r.state.history[e].train_loss, c.state.history[e].train_loss)) << e;
    EXPECT_TRUE(same(r.state.history[e].held_out_loss, c.state.history[e].held_out_loss)) << e;
    EXPECT_TRUE(same(r.state.history[e].seconds, c.state.history[e].seconds)) << e;
  }
  EXPECT_EQ(r.options.epochs, 2);
  EXPECT_EQ(r.options.batch, 16);
  EXPECT_EQ(r.options.lr, 1e-2);
  EXPECT_EQ(r.options.seed, 0xfedcba9876543210ULL);
  EXPECT_TRUE(r.options.variable_pb);
}

TEST(Checkpoint, RoundTripOfAnUntrainedStateAndOfAConstantPbRun) {
  const CheckpointData s;
  TempDir dir;
  const std::string path = (dir.path() / "ckpt.safetensors").string();

  Checkpoint empty{s.fresh, {}, s.options(3)};  // no epoch done, no Adam state
  save_checkpoint(path, empty);
  const Checkpoint e = load_checkpoint(path);
  EXPECT_EQ(e.state.epochs_done, 0);
  EXPECT_TRUE(e.state.history.empty());
  expect_same_adam(e.state.adam, empty.state.adam);

  Checkpoint constant{s.fresh, {}, s.options(1, /*variable_pb=*/false)};
  s.run(constant.model, constant.state, constant.options);
  save_checkpoint(path, constant);
  const Checkpoint c = load_checkpoint(path);
  EXPECT_FALSE(c.options.variable_pb);
  expect_same_adam(c.state.adam, constant.state.adam);  // PB tensor: no moments
  EXPECT_EQ(st::read_file(path).tensors.count("optim.adam.m.pb"), 0u);
  EXPECT_EQ(st::read_file(path).tensors.count("optim.adam.m.dec.bias"), 1u);
}

TEST(Checkpoint, IsNotAPlainModelAndAModelIsNotACheckpoint) {
  const CheckpointData s;
  Checkpoint c{s.fresh, {}, s.options(1)};
  s.run(c.model, c.state, c.options);
  TempDir dir;
  const std::string ckpt = (dir.path() / "ckpt.safetensors").string();
  save_checkpoint(ckpt, c);

  // load_model reads model files only: the optimiser tensors are rejected.
  try {
    load_model(ckpt);
    ADD_FAILURE() << "load_model accepted a checkpoint";
  } catch (const ModelFileError& e) {
    EXPECT_TRUE(contains(e.what(), ckpt + ": unexpected tensor 'optim.adam.")) << e.what();
  }
  // ... but the model inside is complete, read with allow_optimizer_state.
  const HadynetModel inside = model_from_safetensors(st::read_file(ckpt), ckpt, true);
  EXPECT_TRUE(bit_identical(inside.params, c.model.params));

  const std::string model = (dir.path() / "model.safetensors").string();
  save_model(model, c.model);
  try {
    load_checkpoint(model);
    ADD_FAILURE() << "load_checkpoint accepted a model file";
  } catch (const ModelFileError& e) {
    EXPECT_TRUE(contains(e.what(), model + ": a model file, not a checkpoint")) << e.what();
  }
}

TEST(Checkpoint, MalformedCheckpointMetadataOrStateIsAModelFileError) {
  const CheckpointData s;
  Checkpoint c{s.fresh, {}, s.options(1)};
  s.run(c.model, c.state, c.options);
  TempDir dir;
  const std::string path = (dir.path() / "ckpt.safetensors").string();
  save_checkpoint(path, c);
  const st::File good = st::read_file(path);

  const auto expect_error = [&](const st::File& f, const std::string& part) {
    st::write_file(path, f);
    try {
      load_checkpoint(path);
      ADD_FAILURE() << "accepted; expected " << part;
    } catch (const ModelFileError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_EQ(what.find(path, 1), std::string::npos) << "path named twice: " << what;
      EXPECT_TRUE(contains(what, part)) << what;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a ModelFileError: " << e.what();
    }
  };
  st::File f = good;
  f.metadata["checkpoint"] = "{";
  expect_error(f, "checkpoint metadata");
  f = good;
  f.metadata["checkpoint"] = R"({"epochs_done": 1})";
  expect_error(f, "checkpoint metadata");
  f = good;
  f.tensors.erase("optim.adam.v.lstm.weight_hh_l0");
  expect_error(f, "optim.adam.v.lstm.weight_hh_l0");
  f = good;
  f.tensors["optim.adam.m.dec.bias"] = st::make_f32({3}, std::vector<float>(3, 0.0f));
  expect_error(f, "optim.adam.m.dec.bias");
}

TEST(Checkpoint, ResumingContinuesBitForBit) {
  const CheckpointData s;
  // Straight: epochs 1..4.
  HadynetModel straight = s.fresh;
  TrainingState straight_state;
  s.run(straight, straight_state, s.options(4));

  // Stopped after 2, saved, loaded, resumed to 4.
  HadynetModel first = s.fresh;
  TrainingState first_state;
  s.run(first, first_state, s.options(2));
  TempDir dir;
  const std::string path = (dir.path() / "ckpt.safetensors").string();
  save_checkpoint(path, Checkpoint{first, first_state, s.options(2)});
  Checkpoint resumed = load_checkpoint(path);
  resumed.options.epochs = 4;
  std::vector<int> epochs_seen;
  s.run(resumed.model, resumed.state, resumed.options, &epochs_seen);

  EXPECT_EQ(epochs_seen, (std::vector<int>{3, 4}));
  // The run really moved in epochs 3-4 (else the comparison below is vacuous).
  EXPECT_FALSE(bit_identical(resumed.model.params, first.params));
  EXPECT_TRUE(bit_identical(resumed.model.params, straight.params));
  EXPECT_EQ(resumed.model.bn_batches_tracked, straight.bn_batches_tracked);
  EXPECT_EQ(resumed.state.epochs_done, 4);
  expect_same_adam(resumed.state.adam, straight_state.adam);
  ASSERT_EQ(resumed.state.history.size(), 4u);
  for (std::size_t e = 0; e < 4; ++e) {
    EXPECT_EQ(resumed.state.history[e].epoch, static_cast<int>(e) + 1);
    EXPECT_TRUE(same(resumed.state.history[e].train_loss, straight_state.history[e].train_loss)) << e;
    EXPECT_TRUE(same(resumed.state.history[e].held_out_loss, straight_state.history[e].held_out_loss))
        << e;
  }
}

}  // namespace
}  // namespace hadynet::trainer::testing
