#include "harness/image_file.hpp"

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

// jpeglib.h needs FILE and size_t declared before it.
#include <jpeglib.h>
#include <png.h>

#include "core/error.hpp"

namespace omniloc::harness {

namespace {

void append_to_string(png_structp png, png_bytep data, png_size_t n) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), n);
}
void no_flush(png_structp) {}

void check_8bit(const cv::Mat& image, const char* what) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw RuntimeFailure(std::string("cannot encode ") + what + ": not an 8-bit image of 1, 3 or 4 channels");
}

struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};
void jpeg_fail(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegError*>(c->err);
  c->err->format_message(c, e->message);
  std::longjmp(e->jump, 1);
}

struct PngReadError {
  std::jmp_buf jump;
  std::string message;
};
void png_read_fail(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngReadError*>(png_get_error_ptr(png));
  e->message = msg;
  std::longjmp(e->jump, 1);
}
void png_quiet_warning(png_structp, png_const_charp) {}

}  // namespace

// The three codecs report errors by longjmp. Each setjmp sits in a function of its own whose locals
// are plain pointers set before it; everything the codec fills (the output, the row table) belongs
// to the caller, so no C++ object is left half-changed by a jump and no destructor is skipped.
namespace {

bool png_encode(const cv::Mat& image, const std::vector<png_bytep>& rows, std::string* out) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_set_write_fn(png, out, append_to_string, no_flush);
  // OpenCV 4.6's PngEncoder without parameters ("tune parameters for speed"): SUB filter, zlib level 1,
  // Z_RLE strategy. Changing any of them changes every PNG a recording holds, and its checksum.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, 3 /* Z_RLE */);
  const int type = image.channels() == 1 ? PNG_COLOR_TYPE_GRAY : image.channels() == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA;
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows), 8, type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_bgr(png);  // the rows are in OpenCV's BGR(A) order; PNG stores RGB(A)
  png_write_image(png, const_cast<png_bytepp>(rows.data()));
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

struct JpegOut {
  unsigned char* buf = nullptr;
  unsigned long size = 0;  // NOLINT(google-runtime-int): libjpeg's type
};

bool jpeg_encode(const cv::Mat& image, int quality, jpeg_compress_struct* c, JpegError* err, JpegOut* out) {
  c->err = jpeg_std_error(&err->mgr);
  err->mgr.error_exit = jpeg_fail;
  if (setjmp(err->jump)) {
    jpeg_destroy_compress(c);
    return false;
  }
  jpeg_create_compress(c);
  jpeg_mem_dest(c, &out->buf, &out->size);
  c->image_width = static_cast<JDIMENSION>(image.cols);
  c->image_height = static_cast<JDIMENSION>(image.rows);
  c->input_components = image.channels();
  // libjpeg-turbo reads BGR rows itself (what OpenCV 4.6 asks for when the library has JCS_EXTENSIONS).
  c->in_color_space = image.channels() == 3 ? JCS_EXT_BGR : JCS_GRAYSCALE;
  jpeg_set_defaults(c);
  c->restart_interval = 0;
  jpeg_set_quality(c, quality, TRUE);
  jpeg_start_compress(c, TRUE);
  while (c->next_scanline < c->image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(image.ptr<std::uint8_t>(static_cast<int>(c->next_scanline)));
    jpeg_write_scanlines(c, &row, 1);
  }
  jpeg_finish_compress(c);
  jpeg_destroy_compress(c);
  return true;
}

// Reads the rest of a PNG whose 8 signature bytes were read from `f` into `img` (RGB, 8 bits).
bool png_decode(std::FILE* f, PngReadError* err, Image* img, std::vector<png_bytep>* rows) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, err, png_read_fail, png_quiet_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    err->message = "libpng could not start";
    return false;
  }
  if (setjmp(err->jump)) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, f);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  png_uint_32 w = 0, h = 0;
  int depth = 0, type = 0;
  png_get_IHDR(png, info, &w, &h, &depth, &type, nullptr, nullptr, nullptr);
  // The transformations OpenCV 4.6's PngDecoder asks for an 8-bit, 3-channel result.
  if (depth == 16) png_set_strip_16(png);
  png_set_strip_alpha(png);
  if (type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((type & PNG_COLOR_MASK_COLOR) == 0 && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if ((type & PNG_COLOR_MASK_COLOR) == 0) png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != static_cast<png_size_t>(w) * 3) png_error(png, "an unexpected row size after conversion to RGB");
  img->width = static_cast<int>(w);
  img->height = static_cast<int>(h);
  img->rgb.assign(static_cast<std::size_t>(w) * h * 3, 0);
  rows->resize(h);
  for (png_uint_32 y = 0; y < h; ++y) (*rows)[y] = img->rgb.data() + static_cast<std::size_t>(y) * w * 3;
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

std::string encode_png(const cv::Mat& image) {
  check_8bit(image, "PNG");
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y) rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(image.ptr<std::uint8_t>(y));
  std::string out;
  if (!png_encode(image, rows, &out)) throw RuntimeFailure("cannot encode PNG");
  return out;
}

std::string encode_jpeg(const cv::Mat& image, int quality) {
  check_8bit(image, "JPEG");
  if (image.channels() == 4) throw RuntimeFailure("cannot encode JPEG: a 4-channel image");
  jpeg_compress_struct c{};
  JpegError err{};
  JpegOut out;
  const bool ok = jpeg_encode(image, quality, &c, &err, &out);
  std::string bytes = ok ? std::string(reinterpret_cast<const char*>(out.buf), out.size) : std::string();
  std::free(out.buf);
  if (!ok) throw RuntimeFailure(std::string("cannot encode JPEG: ") + err.message);
  return bytes;
}

Image read_png_rgb(const std::string& path) {
  static const char* const kExpected = "a PNG image (recording.json says \"images\": true)";
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw ConfigError(path, "a file that cannot be opened", kExpected);
  png_byte sig[8] = {};
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8) != 0) throw ConfigError(path, "a file that is not a PNG", kExpected);
  PngReadError err;
  Image img;
  std::vector<png_bytep> rows;
  if (!png_decode(f.get(), &err, &img, &rows)) throw ConfigError(path, "a damaged PNG (" + err.message + ")", kExpected);
  return img;
}

}  // namespace omniloc::harness
