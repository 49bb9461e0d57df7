// PNG and JPEG through libpng / libjpeg (harness/image_file.hpp) against OpenCV's imgcodecs, which
// this test alone links: every file written must be the bytes cv::imencode writes (recordings keep
// PNG frames under a checksum), and every PNG read must give the pixels cv::imread(IMREAD_COLOR) gives.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <png.h>

#include "core/error.hpp"
#include "harness/image_file.hpp"

namespace fs = std::filesystem;
using namespace omniloc;
using namespace omniloc::harness;

namespace {

// A seeded image with smooth regions and noise, like a rendered frame (flat colours compress
// differently from noise; both paths of the encoder are exercised).
cv::Mat test_image(int rows, int cols, int type, std::uint32_t seed) {
  std::mt19937 rng(seed);
  cv::Mat m(rows, cols, type);
  const int ch = m.channels();
  const int depth_max = m.depth() == CV_16U ? 65535 : 255;
  std::uniform_int_distribution<int> noise(0, depth_max);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      for (int k = 0; k < ch; ++k) {
        const int v = (r / 8 + c / 16 + k) % 3 == 0 ? noise(rng) : ((r * 7 + c * 3 + k * 50) % 256) * (depth_max / 255);
        if (m.depth() == CV_16U)
          m.ptr<std::uint16_t>(r)[c * ch + k] = static_cast<std::uint16_t>(v);
        else
          m.ptr<std::uint8_t>(r)[c * ch + k] = static_cast<std::uint8_t>(v);
      }
  return m;
}

std::string opencv_bytes(const std::string& ext, const cv::Mat& m, const std::vector<int>& params = {}) {
  std::vector<uchar> buf;
  EXPECT_TRUE(cv::imencode(ext, m, buf, params));
  return std::string(buf.begin(), buf.end());
}

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("omniloc_image_file_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

// A PNG of any colour type, bit depth, palette, transparency and interlacing, written with libpng
// (OpenCV's encoder makes only grey, RGB and RGBA). `pixels`: packed rows as libpng takes them.
void write_raw_png(const fs::path& p, int w, int h, int depth, int type, bool interlace, const std::vector<std::uint8_t>& pixels,
                   bool palette_with_transparency = false, bool grey_transparency = false) {
  std::FILE* f = std::fopen(p.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), depth, type,
               interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  std::vector<png_color> palette;
  if (type == PNG_COLOR_TYPE_PALETTE) {
    for (int i = 0; i < (1 << depth); ++i)
      palette.push_back({static_cast<png_byte>(i * 37 % 256), static_cast<png_byte>(255 - i * 11 % 256), static_cast<png_byte>(i * 5 % 256)});
    png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
    if (palette_with_transparency) {
      std::vector<png_byte> alpha(palette.size());
      for (std::size_t i = 0; i < alpha.size(); ++i) alpha[i] = static_cast<png_byte>(i * 29 % 256);
      png_set_tRNS(png, info, alpha.data(), static_cast<int>(alpha.size()), nullptr);
    }
  }
  if (grey_transparency) {
    png_color_16 t{};
    t.gray = 1;
    png_set_tRNS(png, info, nullptr, 0, &t);
  }
  png_write_info(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  std::vector<png_bytep> rows(static_cast<std::size_t>(h));
  for (int r = 0; r < h; ++r) rows[static_cast<std::size_t>(r)] = const_cast<png_bytep>(pixels.data() + r * row_bytes);
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

// Compares read_png_rgb with cv::imread(IMREAD_COLOR) on a file.
void expect_same_pixels(const fs::path& p) {
  const cv::Mat bgr = cv::imread(p.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(bgr.empty()) << p;
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  const Image img = read_png_rgb(p.string());
  ASSERT_EQ(img.width, rgb.cols) << p;
  ASSERT_EQ(img.height, rgb.rows) << p;
  const std::vector<std::uint8_t> want(rgb.data, rgb.data + rgb.total() * 3);
  EXPECT_EQ(img.rgb, want) << p;
}

}  // namespace

TEST(ImageFile, PngBytesEqualOpenCvsForGreyBgrAndBgra) {
  std::uint32_t seed = 1;
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4})
    for (const auto& [rows, cols] : std::vector<std::pair<int, int>>{{1, 1}, {3, 17}, {64, 64}, {480, 640}}) {
      const cv::Mat m = test_image(rows, cols, type, seed++);
      EXPECT_EQ(encode_png(m), opencv_bytes(".png", m)) << "type " << type << " " << rows << "x" << cols;
    }
  // A view into a larger image (rows not contiguous) as OpenCV takes it.
  const cv::Mat big = test_image(100, 120, CV_8UC3, 99);
  const cv::Mat roi = big(cv::Rect(7, 5, 50, 40));
  EXPECT_EQ(encode_png(roi), opencv_bytes(".png", roi));
}

TEST(ImageFile, JpegBytesEqualOpenCvsAtQuality88) {
  for (const int type : {CV_8UC1, CV_8UC3}) {
    const cv::Mat m = test_image(240, 320, type, 7);
    EXPECT_EQ(encode_jpeg(m, 88), opencv_bytes(".jpg", m, {cv::IMWRITE_JPEG_QUALITY, 88})) << "type " << type;
    EXPECT_EQ(encode_jpeg(m, 40), opencv_bytes(".jpg", m, {cv::IMWRITE_JPEG_QUALITY, 40})) << "type " << type;
  }
}

TEST(ImageFile, OnlyEightBitImagesOfOneThreeOrFourChannelsAreEncoded) {
  EXPECT_THROW(encode_png(cv::Mat()), RuntimeFailure);
  EXPECT_THROW(encode_png(cv::Mat(4, 4, CV_16UC3, cv::Scalar(1))), RuntimeFailure);
  EXPECT_THROW(encode_png(cv::Mat(4, 4, CV_8UC2, cv::Scalar(1))), RuntimeFailure);
  EXPECT_THROW(encode_jpeg(cv::Mat(4, 4, CV_8UC4, cv::Scalar(1)), 88), RuntimeFailure);
}

TEST(ImageFile, ReadsEveryPngKindAsImreadColorDoes) {
  const fs::path dir = temp_dir();
  int n = 0;
  // What OpenCV itself writes: grey, BGR and BGRA in 8 and 16 bits.
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    const fs::path p = dir / ("cv_" + std::to_string(n++) + ".png");
    write_bytes(p, opencv_bytes(".png", test_image(37, 53, type, static_cast<std::uint32_t>(type + 3))));
    expect_same_pixels(p);
  }
  // The rest of the format: grey of 1, 2, 4 bits, grey + alpha, palettes with and without
  // transparency, a grey transparency colour, Adam7 interlacing.
  struct Kind {
    int depth, type;
    bool interlace, palette_alpha, grey_alpha;
  };
  const std::vector<Kind> kinds = {
      {1, PNG_COLOR_TYPE_GRAY, false, false, false},       {2, PNG_COLOR_TYPE_GRAY, false, false, false},
      {4, PNG_COLOR_TYPE_GRAY, true, false, false},        {8, PNG_COLOR_TYPE_GRAY, false, false, true},
      {8, PNG_COLOR_TYPE_GRAY_ALPHA, false, false, false}, {16, PNG_COLOR_TYPE_GRAY_ALPHA, false, false, false},
      {1, PNG_COLOR_TYPE_PALETTE, false, false, false},    {4, PNG_COLOR_TYPE_PALETTE, false, true, false},
      {8, PNG_COLOR_TYPE_PALETTE, true, true, false},      {8, PNG_COLOR_TYPE_RGB, true, false, false},
      {16, PNG_COLOR_TYPE_RGB_ALPHA, true, false, false},
  };
  std::mt19937 rng(5);
  for (const Kind& k : kinds) {
    const int w = 29, h = 23;
    const int channels = k.type == PNG_COLOR_TYPE_GRAY_ALPHA ? 2 : k.type == PNG_COLOR_TYPE_RGB ? 3 : k.type == PNG_COLOR_TYPE_RGB_ALPHA ? 4 : 1;
    const std::size_t row_bytes = (static_cast<std::size_t>(w) * channels * k.depth + 7) / 8;
    std::vector<std::uint8_t> px(row_bytes * h);
    for (auto& b : px) b = static_cast<std::uint8_t>(rng());
    const fs::path p = dir / ("raw_" + std::to_string(n++) + ".png");
    write_raw_png(p, w, h, k.depth, k.type, k.interlace, px, k.palette_alpha, k.grey_alpha);
    expect_same_pixels(p);
  }
  fs::remove_all(dir);
}

TEST(ImageFile, AFileThatIsNotAReadablePngIsAConfigErrorNamingIt) {
  const fs::path dir = temp_dir();
  const std::string good = opencv_bytes(".png", test_image(40, 40, CV_8UC3, 11));
  write_bytes(dir / "text.png", "hello, not a picture");
  write_bytes(dir / "cut.png", good.substr(0, good.size() / 2));
  write_bytes(dir / "empty.png", "");
  write_bytes(dir / "jpeg.png", opencv_bytes(".jpg", test_image(8, 8, CV_8UC3, 1)));
  std::string flipped = good;
  flipped[good.size() / 2] = static_cast<char>(flipped[good.size() / 2] ^ 0x55);  // a bit error inside IDAT: its CRC fails
  write_bytes(dir / "flipped.png", flipped);
  for (const char* name : {"text.png", "cut.png", "empty.png", "jpeg.png", "flipped.png"}) {
    try {
      (void)read_png_rgb((dir / name).string());
      ADD_FAILURE() << name << " was read";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.path(), (dir / name).string());
      EXPECT_NE(e.value().find(std::string(name) == "cut.png" || std::string(name) == "flipped.png" ? "damaged PNG" : "not a PNG"), std::string::npos)
          << name << ": " << e.value();
    }
  }
  EXPECT_THROW((void)read_png_rgb((dir / "missing.png").string()), ConfigError);
  fs::remove_all(dir);
}
