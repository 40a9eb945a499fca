#include "test/usb/usb_test_images.h"

#include <stdexcept>

#include "firmware/app/model_store.h"
#include "hadynet_model_q15.h"
#include "test/usb/test_bytes.h"

namespace hadynet::usb::testing {

namespace mu = model_update;

const ImageKey& device_key() {
  static const ImageKey key = mu::test::signing_key(0x51);
  return key;
}

const ImageKey& stranger_key() {
  static const ImageKey key = mu::test::signing_key(0x52);
  return key;
}

mu::ModelIdentity firmware_identity() { return app::model_identity<model_q15::Model>(); }

mu::ModelIdentity small_identity() {
  mu::ModelIdentity id = firmware_identity();
  id.payload_length = 3000;
  return id;
}

Bytes make_image(const mu::ModelIdentity& identity, const ImageSpec& spec, const ImageKey& key, HeaderEdit edit) {
  mu::ModelImageHeader header = mu::test::header_for(identity, spec.sequence);
  header.downgrade_allowed = spec.downgrade_allowed;
  header.model_hash = spec.model_hash ^ spec.sequence;
  if (edit != nullptr) edit(header);
  // An edit of the payload length makes a payload of that length.
  const Bytes payload = test_data::pseudo_random(header.payload_length, spec.payload_seed);
  return mu::test::sign_image(header, payload, key);
}

mu::ModelImageHeader header_of_file(const Bytes& file) {
  if (file.size() < mu::kImageHeaderSize) throw std::runtime_error("not an image: shorter than its header");
  mu::ModelImageHeader h;
  if (mu::decode_model_image_header(std::span<const std::uint8_t, mu::kImageHeaderSize>(file.data(),
                                                                                        mu::kImageHeaderSize),
                                    h) != mu::HeaderFormat::kWellFormed) {
    throw std::runtime_error("not an image: malformed header");
  }
  return h;
}

}  // namespace hadynet::usb::testing
