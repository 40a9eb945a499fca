// A model image file as `hadynet flash --model` sends it (docs/usb.md,
// "Model images"; the format is firmware/model_update/model_image.h: a
// 256-byte header, then the payload), checked on the host before any device
// is touched: the header decodes (the firmware's own decoder) and the file
// is exactly header + payload length bytes. Whether the image suits a
// device (identity, key, signature, sequence) is the device's to decide.
#ifndef HADYNET_TOOLS_USB_MODEL_IMAGE_FILE_H_
#define HADYNET_TOOLS_USB_MODEL_IMAGE_FILE_H_

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "firmware/model_update/model_image.h"

namespace hadynet::tools::usb {

// The file is not a model image; the message names the file and the defect.
class ModelImageFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ModelImageFile {
  std::vector<std::uint8_t> bytes;  // the whole file
  model_update::ModelImageHeader header;
};

// Reads and checks `path`; throws ModelImageFileError.
ModelImageFile load_model_image_file(const std::filesystem::path& path);
// The same checks on bytes already read (`name` goes into the messages).
ModelImageFile check_model_image_bytes(std::vector<std::uint8_t> bytes, const std::string& name);

// The repository's development key (keys/development.key.pub, whose secret
// half is public), as the build read it.
const std::array<std::uint8_t, model_update::kPublicKeyBytes>& development_public_key();
bool is_development_key(std::span<const std::uint8_t, model_update::kPublicKeyBytes> key);

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_MODEL_IMAGE_FILE_H_
