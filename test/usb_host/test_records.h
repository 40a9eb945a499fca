// What the usb_host tests share: the hand's identity as the host sees it
// (written from docs/usb.md, not taken from the firmware's tables), its
// address on the testbed, and the telemetry records they publish.
#ifndef HADYNET_TEST_USB_HOST_TEST_RECORDS_H_
#define HADYNET_TEST_USB_HOST_TEST_RECORDS_H_

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include "firmware/app/period_record.h"
#include "test/usb_host/hand_device.h"

namespace hadynet::usb::host_testing {

constexpr std::uint16_t kVid = 0x1209;
constexpr std::uint16_t kPid = 0x0001;
constexpr std::uint8_t kHandDevnum = 2;

// A record with every field exercised: -0.0 (sequence 2) and a NaN payload
// in prediction[0] that must survive bit for bit.
inline app::PeriodRecord<Q> record(std::uint32_t sequence) {
  app::PeriodRecord<Q> r;
  r.sequence = sequence;
  r.period = sequence + 2;
  r.mode = sequence % 2 == 0 ? firmware::Mode::kDetect : firmware::Mode::kControl;
  r.flags = static_cast<std::uint16_t>(app::kRecordPredictionValid | app::kRecordDistanceValid | app::kRecordStepped |
                                       (sequence % 2 == 0 ? 0 : app::kRecordContact | app::kRecordCommandValid));
  r.muscle_state_age = sequence % 3;
  r.overruns = 1;
  r.missed_periods = 2;
  for (int i = 0; i < app::PeriodRecord<Q>::kLoadcells; ++i) r.loadcells_N[i] = 0.25f * float(i) - float(sequence);
  r.d = sequence == 2 ? -0.0f : 3.5f * float(sequence);
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = float(i) / 7.0f + float(sequence);
  std::uint32_t nan_bits = 0x7FC01234u + sequence;  // a NaN payload must survive
  std::memcpy(&r.prediction[0], &nan_bits, sizeof nan_bits);
  if (r.has(app::kRecordCommandValid)) {
    for (int i = 0; i < Q::kU; ++i) r.command[i] = -float(i) * 0.125f;
  }
  if (sequence % 3 != 0) {  // on-device recognition in two records of three
    r.flags |= app::kRecordRecognition;
    r.adapt_updates = sequence;
    r.recognized_state = static_cast<std::uint16_t>(sequence % Q::kStates);
    r.recognized_distance = 0.0625f * float(sequence);
    r.other_object_state = sequence % 3 == 1 ? app::kRecordNoOtherObject : std::uint16_t{0};
    r.other_object_distance = sequence % 3 == 1 ? 0.0f : 1.5f;
  }
  return r;
}

inline void expect_same_bits(const app::PeriodRecord<Q>& got, const app::PeriodRecord<Q>& want) {
  EXPECT_EQ(got.sequence, want.sequence);
  EXPECT_EQ(got.period, want.period);
  EXPECT_EQ(got.mode, want.mode);
  EXPECT_EQ(got.flags, want.flags);
  EXPECT_EQ(got.muscle_state_age, want.muscle_state_age);
  EXPECT_EQ(got.overruns, want.overruns);
  EXPECT_EQ(got.missed_periods, want.missed_periods);
  EXPECT_EQ(std::memcmp(got.loadcells_N, want.loadcells_N, sizeof want.loadcells_N), 0);
  EXPECT_EQ(std::memcmp(&got.d, &want.d, sizeof want.d), 0);
  EXPECT_EQ(std::memcmp(got.prediction, want.prediction, sizeof want.prediction), 0);
  EXPECT_EQ(std::memcmp(got.command, want.command, sizeof want.command), 0);
  EXPECT_EQ(got.adapt_updates, want.adapt_updates);
  EXPECT_EQ(got.recognized_state, want.recognized_state);
  EXPECT_EQ(std::memcmp(&got.recognized_distance, &want.recognized_distance, sizeof(float)), 0);
  EXPECT_EQ(got.other_object_state, want.other_object_state);
  EXPECT_EQ(std::memcmp(&got.other_object_distance, &want.other_object_distance, sizeof(float)), 0);
}

// The same record with prediction[0] finite (a HADYNET log cannot hold a
// NaN: `hadynet monitor` leaves such records out of its CSV).
inline app::PeriodRecord<Q> finite_record(std::uint32_t sequence) {
  app::PeriodRecord<Q> r = record(sequence);
  r.prediction[0] = 0.5f * float(sequence);
  return r;
}

inline std::string narrow(const wchar_t* w) {
  std::string out;
  for (; w != nullptr && *w != 0; ++w) out.push_back(static_cast<char>(*w));
  return out;
}

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_TEST_RECORDS_H_
