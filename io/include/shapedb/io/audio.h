#pragma once
// Sound files: WAV (RIFF, 16-bit PCM, mono), what every player and audio tool reads.
#include <filesystem>
#include <span>

#include <shapedb/core/result.h>

namespace shapedb::io {

/// Writes `samples` (clamped to [−1, 1]) as a 16-bit PCM mono WAV file at `sampleRate`.
/// Errors: kInvalidArgument (a rate outside 1 to 1,000,000 Hz), kIo naming the file.
Status saveWav(std::span<const float> samples, int sampleRate, const std::filesystem::path& path);

}  // namespace shapedb::io
