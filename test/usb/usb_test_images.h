// Signed model images for the USB tests (firmware/model_update/model_image.h:
// a 256-byte header, then the payload), signed on the host with libsodium by
// test/model_update/signed_images.h with keys generated from fixed seeds.
// The devices of usb_test_device.h trust device_key().
#ifndef HADYNET_TEST_USB_USB_TEST_IMAGES_H_
#define HADYNET_TEST_USB_USB_TEST_IMAGES_H_

#include <cstdint>
#include <vector>

#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_image.h"
#include "test/model_update/signed_images.h"

namespace hadynet::usb::testing {

using Bytes = std::vector<std::uint8_t>;
using ImageKey = model_update::test::SigningKey;

// The key the test devices trust, and one they do not.
const ImageKey& device_key();
const ImageKey& stranger_key();

// What images for the build's q15 firmware must match (app::model_identity).
model_update::ModelIdentity firmware_identity();
// A small model (3000 payload bytes) for tests that repeat whole updates.
model_update::ModelIdentity small_identity();

struct ImageSpec {
  std::uint32_t sequence = 1;
  std::uint32_t payload_seed = 1;  // pseudo-random payload of the identity's length
  bool downgrade_allowed = false;
  std::uint64_t model_hash = 0x5EED0000DA7A0000ull;  // the header's information field
};

// The header (filled for `identity` by header_for) adjusted before signing;
// the payload has the header's payload length after the edit.
using HeaderEdit = void (*)(model_update::ModelImageHeader&);

// A signed image file of `identity`.
Bytes make_image(const model_update::ModelIdentity& identity, const ImageSpec& spec, const ImageKey& key = device_key(),
                 HeaderEdit edit = nullptr);

// The image's header fields (decoded from its first 256 bytes).
model_update::ModelImageHeader header_of_file(const Bytes& file);

}  // namespace hadynet::usb::testing

#endif  // HADYNET_TEST_USB_USB_TEST_IMAGES_H_
