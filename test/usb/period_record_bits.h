// Bit-for-bit equality of two app::PeriodRecords, field by field (the
// struct has padding, so a whole-object memcmp would compare indeterminate
// bytes). Floats are compared as bit patterns: -0.0 and NaN payloads count.
#ifndef HADYNET_TEST_USB_PERIOD_RECORD_BITS_H_
#define HADYNET_TEST_USB_PERIOD_RECORD_BITS_H_

#include <gtest/gtest.h>

#include <cstring>

#include "firmware/app/period_record.h"

namespace hadynet::usb::testing {

template <firmware::GeneratedModel M>
void expect_same_bits(const app::PeriodRecord<M>& got, const app::PeriodRecord<M>& want, int where = 0) {
  EXPECT_EQ(got.sequence, want.sequence) << where;
  EXPECT_EQ(got.period, want.period) << where;
  EXPECT_EQ(got.mode, want.mode) << where;
  EXPECT_EQ(got.flags, want.flags) << where;
  EXPECT_EQ(got.muscle_state_age, want.muscle_state_age) << where;
  EXPECT_EQ(got.overruns, want.overruns) << where;
  EXPECT_EQ(got.missed_periods, want.missed_periods) << where;
  EXPECT_EQ(std::memcmp(got.loadcells_N, want.loadcells_N, sizeof want.loadcells_N), 0) << "loadcells " << where;
  EXPECT_EQ(std::memcmp(&got.d, &want.d, sizeof want.d), 0) << "d " << where;
  EXPECT_EQ(std::memcmp(got.prediction, want.prediction, sizeof want.prediction), 0) << "prediction " << where;
  EXPECT_EQ(std::memcmp(got.command, want.command, sizeof want.command), 0) << "command " << where;
  EXPECT_EQ(got.adapt_updates, want.adapt_updates) << where;
  EXPECT_EQ(got.recognized_state, want.recognized_state) << where;
  EXPECT_EQ(std::memcmp(&got.recognized_distance, &want.recognized_distance, sizeof(float)), 0) << where;
  EXPECT_EQ(got.other_object_state, want.other_object_state) << where;
  EXPECT_EQ(std::memcmp(&got.other_object_distance, &want.other_object_distance, sizeof(float)), 0) << where;
}

}  // namespace hadynet::usb::testing

#endif  // HADYNET_TEST_USB_PERIOD_RECORD_BITS_H_
