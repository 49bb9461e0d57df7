#pragma once
// Colour classification by look-up table (paper 002: an off-line colour table). The table is
// indexed by RGB quantised to `bits` per channel (6 bits: 64^3 cells) and learned from labelled
// images by majority vote per cell; empty cells take the class of the nearest learned cell within a
// few steps (so colours shifted by noise still classify), else "unknown". RGB rather than YUV: the
// renderer's colours differ in brightness and saturation, which RGB cells separate as well, and no
// conversion is needed per pixel.
#include <cstdint>
#include <string>
#include <vector>

#include "core/messages.hpp"

namespace omniloc {

enum ColourClass : std::uint8_t {
  kUnknown = 0,
  kFieldGreen = 1,
  kLineWhite = 2,
  kBallOrange = 3,
  kObstacleBlack = 4,
  kOwnBody = 5,
  kYellow = 6,
  kBlue = 7,
  kRed = 8,
  kNumClasses = 12,
};

/// Name of a colour class as used in field files ("yellow", "blue", "red", "green" for the carpet,
/// "white", "orange", "black", ...); "unknown" for anything else.
std::string colour_class_name(std::uint8_t c);
/// The class of a landmark/goal colour name ("yellow", "blue", "red"); kUnknown for colours the
/// table has no class for (e.g. "magenta", "cyan", "white").
ColourClass landmark_colour_class(const std::string& name);

class ColourTable {
 public:
  explicit ColourTable(int bits = 6);
  /// Learns from pairs of images and label images (class id per pixel in channel 0).
  void learn(const std::vector<Image>& images, const std::vector<Image>& labels, int min_count = 2, int fill_radius = 3);
  std::uint8_t classify(const std::uint8_t* rgb) const { return lookup()(rgb); }
  /// classify() by value, for loops over many pixels: its fields stay in registers where the
  /// table's members would be reloaded after every store through a byte pointer (which may alias them).
  struct Lookup {
    const std::uint8_t* lut;
    int shift, bits;
    std::uint8_t operator()(const std::uint8_t* rgb) const {
      return lut[((rgb[0] >> shift) << (2 * bits)) | ((rgb[1] >> shift) << bits) | (rgb[2] >> shift)];
    }
  };
  Lookup lookup() const { return {lut_.data(), 8 - bits_, bits_}; }
  int bits() const { return bits_; }
  /// The field the table was learned for (fingerprint); a table of another field is refused.
  std::string field;
  void save(const std::string& path) const;
  /// Throws ConfigError naming the file when it is missing, malformed, or of another field.
  static ColourTable load(const std::string& path, const std::string& expected_field = "");

 private:
  int bits_;
  std::vector<std::uint8_t> lut_;
};

}  // namespace omniloc
