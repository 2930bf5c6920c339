// abcube.compare, abcube.read_image, abcube.write_image: numpy arrays in and out of the
// library's image I/O and error figures (include/abcube/image.hpp).
#include <cmath>
#include <string>

#include "py_convert.hpp"

namespace abcube {

namespace {

// The error figures of `abcube compare`, as a dict.
py::dict compare(const py::handle& a, const py::handle& b) {
  const Image image_a = array_to_image(a, "compare: a");
  const Image image_b = array_to_image(b, "compare: b");
  if (image_a.width != image_b.width || image_a.height != image_b.height || image_a.channels != image_b.channels) {
    auto shape = [](const Image& i) {
      return std::to_string(i.height) + " x " + std::to_string(i.width) + " x " + std::to_string(i.channels);
    };
    throw InputError("compare: the images differ in shape: a is " + shape(image_a) + ", b is " + shape(image_b));
  }
  ImageError error;
  {
    py::gil_scoped_release release;
    error = image_error(image_a, image_b);
  }
  py::dict out;
  out["rmse"] = error.rmse;
  out["psnr_db"] = error.psnr;  // +inf for identical images
  out["max_abs"] = error.max_abs;
  out["share_over_1_255"] = error.share_over_1;
  out["share_over_2_255"] = error.share_over_2;
  out["share_over_8_255"] = error.share_over_8;
  out["worst_pixel"] = py::make_tuple(error.worst_x, error.worst_y);
  out["worst_channel"] = std::string(1, "RGB"[error.worst_channel]);
  out["linear_rmse"] = error.linear_rmse;
  out["linear_max_abs"] = error.linear_max_abs;
  out["relative_mean"] = error.relative_mean;
  out["hdr"] = error.hdr;
  // The difference image: |a - b| per channel, linear, the shape of the inputs.
  Image diff(image_a.width, image_a.height, image_a.channels);
  for (size_t i = 0; i < diff.data.size(); ++i) diff.data[i] = std::abs(image_a.data[i] - image_b.data[i]);
  out["diff"] = image_to_array(std::move(diff));
  return out;
}

py::array read(const py::handle& path_object) {
  const std::string path = path_arg(path_object, "read_image: path");
  Image image;
  {
    py::gil_scoped_release release;
    image = read_image(path);
  }
  return image_to_array(std::move(image));
}

void write(const py::handle& path_object, const py::handle& array) {
  const std::string path = path_arg(path_object, "write_image: path");
  if (!image_format_supported(path)) {
    std::string known;
    for (const std::string& e : writable_image_extensions()) known += (known.empty() ? "" : ", ") + e;
    throw InputError(path + ": no image writer for this file extension (" + known + ")");
  }
  const Image image = array_to_image(array, "write_image: image");
  py::gil_scoped_release release;
  write_image(path, image);
}

}  // namespace

void bind_image(py::module_& m) {
  m.def("compare", &compare, py::arg("a"), py::arg("b"),
        R"doc(Error of image `a` against image `b` (float arrays of one shape, H x W x C),
as `abcube compare` prints it, on sRGB-encoded values clamped to [0, 1]:
"rmse", "psnr_db" (inf when identical), "max_abs", "share_over_1_255", "share_over_2_255",
"share_over_8_255" (shares of pixels whose largest channel differs by more than 1/255,
2/255, 8/255), "worst_pixel" ((x, y) of the largest difference, first in reading order)
and "worst_channel" ("R", "G" or "B"); on the linear values themselves (HDR included):
"linear_rmse", "linear_max_abs", "relative_mean" (mean of |a - b| / max(|b|, 1/255)) and
"hdr" (a value above 1 in either); and "diff", the difference image |a - b| (float32, the
inputs' shape).)doc");
  m.def("read_image", &read, py::arg("path"),
        R"doc(Reads an image file (format by extension) as a float32 array H x W x C
(H x W for one channel), linear: sRGB-encoded files (PNG, JPEG) are decoded.)doc");
  m.def("write_image", &write, py::arg("path"), py::arg("image"),
        R"doc(Writes a float array (H x W, H x W x C; linear values) to `path`, format by
extension: float formats (EXR) keep the values, 8-bit ones (PNG) get sRGB-encoded values.
Atomic: a temporary file renamed into place, never a partial file.)doc");
  m.def(
      "remove_stale_temporaries",
      [](const py::handle& folder) { return remove_stale_temporaries(path_arg(folder, "folder")); }, py::arg("folder"),
      R"doc(Removes from `folder` the temporary files of write_image (and of the abcube program)
that processes of this host left when they were killed before renaming them into place
(".NAME.tmpPID-HOST.EXT", their process gone), and returns how many. Temporaries of live
processes and of other hosts stay. `abcube batch` does this for its output folders before it
renders; a recipe that writes files from workers that may be killed calls it before its own
writes.)doc");
}

}  // namespace abcube
