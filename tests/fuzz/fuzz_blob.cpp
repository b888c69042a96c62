// Fuzz target: the decoders of the database's blobs (io/src/codec.h), which read bytes that a damaged or
// hostile file may hold. The first byte picks the decoder, the rest is the blob. Checked beyond "no
// crash, no leak, no UB, no allocation the blob cannot pay for": whatever decodes re-encodes into a blob
// that decodes again (the encoder never writes what the decoder refuses). It found modes whose finite
// scale times a 16-bit value overflowed to infinity: the decoders now refuse non-finite values.

#include "../../io/src/codec.h"
#include "fuzz_support.h"

namespace shapedb::fuzz {
namespace {

template <typename Decode, typename Encode>
void roundTrip(const std::uint8_t* blob, std::size_t size, Decode decode, Encode encode) {
  auto decoded = decode(blob, size);
  if (!decoded) return;
  const io::Bytes again = encode(*decoded);
  SHAPEDB_FUZZ_CHECK(decode(again.data(), again.size()).ok());
}

}  // namespace
}  // namespace shapedb::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace shapedb;
  if (size == 0) return 0;
  const std::uint8_t* blob = data + 1;
  const std::size_t blobSize = size - 1;
  switch (data[0] % 6) {
    case 0:
      fuzz::roundTrip(blob, blobSize, io::decodeDescriptor, io::encodeDescriptor);
      break;
    case 1:
      fuzz::roundTrip(blob, blobSize, io::decodeTetMesh, io::encodeTetMesh);
      break;
    case 2:
      fuzz::roundTrip(blob, blobSize, io::decodeModes, io::encodeModes);
      break;
    case 3:
      fuzz::roundTrip(blob, blobSize, io::decodeMassProperties, io::encodeMassProperties);
      break;
    case 4:
      fuzz::roundTrip(blob, blobSize, io::decodeCollision, io::encodeCollision);
      break;
    default:
      fuzz::roundTrip(blob, blobSize, io::decodeSound, io::encodeSound);
      break;
  }
  return 0;
}
