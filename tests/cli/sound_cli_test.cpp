// shapedb sound as a user runs it: the WAV read back, its spectrum peaking at the adapted modes.

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <fstream>
#include <unsupported/Eigen/FFT>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "cli_test_support.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

struct Wav {
  int sampleRate = 0;
  std::vector<double> samples;
};

/// Reads the 16-bit PCM mono WAV that saveWav writes (a fixed 44-byte header), checking the header.
Wav readWav(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), {});
  Wav wav;
  EXPECT_GE(bytes.size(), 44u);
  if (bytes.size() < 44) return wav;
  auto u32 = [&](std::size_t at) {
    return static_cast<std::uint32_t>(bytes[at] | bytes[at + 1] << 8 | bytes[at + 2] << 16 |
                                      bytes[at + 3] << 24);
  };
  auto u16 = [&](std::size_t at) { return static_cast<std::uint16_t>(bytes[at] | bytes[at + 1] << 8); };
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 4), "RIFF");
  EXPECT_EQ(std::string(bytes.begin() + 8, bytes.begin() + 16), "WAVEfmt ");
  EXPECT_EQ(u16(20), 1);  // PCM
  EXPECT_EQ(u16(22), 1);  // mono
  EXPECT_EQ(u16(34), 16);
  EXPECT_EQ(u32(40), bytes.size() - 44);
  wav.sampleRate = static_cast<int>(u32(24));
  for (std::size_t at = 44; at + 1 < bytes.size(); at += 2)
    wav.samples.push_back(static_cast<std::int16_t>(u16(at)) / 32767.0);
  return wav;
}

TEST(SoundCli, TheStrongestPeakOfTheSpectrumIsAnAdaptedModalFrequency) {
  test::ScratchDir dir("sound-cli");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 6, "box,ellipsoid", 8).exitCode, 0);
  // A rubber block: its modes ring at a few hundred hertz.
  const auto block = dir / "block.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.4, 0.25, 0.1}), block).ok());
  test::ProcessResult q = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), block.string(), "--material", "rubber", "--json", "--no-fidelity"});
  ASSERT_EQ(q.exitCode, 0) << q.err;
  std::vector<double> modes;
  const nlohmann::json answer = nlohmann::json::parse(q.out);
  for (const auto& f : answer["queries"][0]["physics"]["frequencies_hz"])
    modes.push_back(f.get<double>());
  ASSERT_EQ(modes.size(), 8u);
  ASSERT_LT(modes[0], 5000.0);

  const auto wavPath = dir / "block.wav";
  test::ProcessResult s =
      test::runProcess(SHAPEDB_CLI, {"sound", db.string(), block.string(), "--material", "rubber", "--out",
                                     wavPath.string(), "--seconds", "1"});
  ASSERT_EQ(s.exitCode, 0) << s.err;
  EXPECT_NE(s.out.find("modes ring"), std::string::npos) << s.out;
  const Wav wav = readWav(wavPath);
  ASSERT_EQ(wav.sampleRate, 44100);
  ASSERT_EQ(wav.samples.size(), 44100u);
  const double peak = std::abs(*std::max_element(
      wav.samples.begin(), wav.samples.end(), [](double a, double b) { return std::abs(a) < std::abs(b); }));
  EXPECT_NEAR(peak, 0.9, 0.01);

  // The spectrum (1 Hz bins): its strongest peak below 10 kHz lies on one of the adapted frequencies.
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, wav.samples);
  std::size_t strongest = 1;
  for (std::size_t bin = 1; bin < 10000 && bin < spectrum.size() / 2; ++bin)
    if (std::abs(spectrum[bin]) > std::abs(spectrum[strongest])) strongest = bin;
  const double f = static_cast<double>(strongest) * wav.sampleRate / static_cast<double>(wav.samples.size());
  const double nearest = *std::min_element(
      modes.begin(), modes.end(), [&](double a, double b) { return std::abs(a - f) < std::abs(b - f); });
  EXPECT_LT(std::abs(f - nearest), std::max(2.0, 0.002 * nearest)) << "peak at " << f << " Hz";
  // And it is a peak: half way to the next mode the spectrum is far weaker.
  const auto quiet = static_cast<std::size_t>(std::lround(0.5 * (modes[0] + modes[1])));
  if (modes[1] - modes[0] > 20.0) {
    EXPECT_LT(std::abs(spectrum[quiet]), 0.1 * std::abs(spectrum[strongest]));
  }
}

TEST(SoundCli, AnObjectThatRingsAboveHearingIsAClearError) {
  test::ScratchDir dir("sound-cli-errors");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 2, "box", 4).exitCode, 0);
  const auto bead = dir / "bead.obj";  // a 1 cm steel cube: its first mode is far above 20 kHz
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.01, 0.01, 0.01}), bead).ok());
  test::ProcessResult s =
      test::runProcess(SHAPEDB_CLI, {"sound", db.string(), bead.string(), "--out", (dir / "b.wav").string()});
  EXPECT_EQ(s.exitCode, 1);
  EXPECT_NE(s.err.find("no mode rings below"), std::string::npos) << s.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "b.wav"));
  test::ProcessResult badImpact = test::runProcess(
      SHAPEDB_CLI,
      {"sound", db.string(), bead.string(), "--out", (dir / "b.wav").string(), "--impact", "1,2"});
  EXPECT_EQ(badImpact.exitCode, 2);
}

}  // namespace
}  // namespace shapedb::cli
