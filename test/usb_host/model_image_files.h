// Model image files for the tests against the hand (hand_device.h), made as
// a user makes them: this build's `hadynet model-image` (a child process)
// from the build's model (HADYNET_MODEL), signed with the repository's
// development key, which the hand trusts, or with a key `hadynet keygen`
// makes (which it does not).
#ifndef HADYNET_TEST_USB_HOST_MODEL_IMAGE_FILES_H_
#define HADYNET_TEST_USB_HOST_MODEL_IMAGE_FILES_H_

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {

// keys/development.key: the key the hand trusts.
std::filesystem::path development_key_file();

// `hadynet model-image <build's model> --key KEY --sequence N --out DIR/NAME`;
// the image's path (empty, with a test failure added, if the CLI failed).
std::filesystem::path make_model_image(UsbTestbed& bus, const std::filesystem::path& dir, std::uint32_t sequence,
                                       const std::filesystem::path& key = development_key_file());

// `hadynet keygen --out DIR/other.key`: a key the hand does not trust.
std::filesystem::path make_other_key(UsbTestbed& bus, const std::filesystem::path& dir);

std::vector<std::uint8_t> read_file(const std::filesystem::path& path);

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_MODEL_IMAGE_FILES_H_
