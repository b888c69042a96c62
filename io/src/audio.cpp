#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>

#include <shapedb/io/audio.h>

namespace shapedb::io {

namespace {

void put32(std::ofstream& out, std::uint32_t v) {
  const char bytes[4] = {static_cast<char>(v & 0xff), static_cast<char>((v >> 8) & 0xff),
                         static_cast<char>((v >> 16) & 0xff), static_cast<char>((v >> 24) & 0xff)};
  out.write(bytes, 4);
}

void put16(std::ofstream& out, std::uint16_t v) {
  const char bytes[2] = {static_cast<char>(v & 0xff), static_cast<char>((v >> 8) & 0xff)};
  out.write(bytes, 2);
}

}  // namespace

Status saveWav(std::span<const float> samples, int sampleRate, const std::filesystem::path& path) {
  if (sampleRate < 1 || sampleRate > 1000000)
    return Error{ErrorCode::kInvalidArgument, "a WAV sample rate must be 1 to 1,000,000 Hz"};
  if (samples.size() > (0xffffffffu - 36u) / 2u)
    return Error{ErrorCode::kInvalidArgument, path.string() + ": too many samples for a WAV file"};
  std::ofstream out(path, std::ios::binary);
  if (!out) return Error{ErrorCode::kIo, path.string() + ": cannot open for writing"};
  const auto dataBytes = static_cast<std::uint32_t>(2 * samples.size());
  out.write("RIFF", 4);
  put32(out, 36 + dataBytes);
  out.write("WAVE", 4);
  out.write("fmt ", 4);
  put32(out, 16);  // PCM format chunk
  put16(out, 1);   // PCM
  put16(out, 1);   // mono
  put32(out, static_cast<std::uint32_t>(sampleRate));
  put32(out, static_cast<std::uint32_t>(sampleRate) * 2);  // bytes per second
  put16(out, 2);                                           // bytes per frame
  put16(out, 16);                                          // bits per sample
  out.write("data", 4);
  put32(out, dataBytes);
  for (float s : samples) {
    const float clamped = std::isfinite(s) ? std::clamp(s, -1.0f, 1.0f) : 0.0f;
    put16(out, static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(clamped * 32767.0f))));
  }
  out.flush();
  if (!out) return Error{ErrorCode::kIo, path.string() + ": write failed"};
  return Ok{};
}

}  // namespace shapedb::io
