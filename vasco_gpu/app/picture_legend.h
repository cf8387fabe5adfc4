// picture_legend.h — text and a legend on RGB pictures, for mapdiff's
// --png: a tiny built-in 5 x 7 bitmap font (upper case letters, digits and
// a little punctuation; anything else is drawn as a blank) and the legend
// that explains the difference picture's colours.
#ifndef VASCO_GPU_APP_PICTURE_LEGEND_H
#define VASCO_GPU_APP_PICTURE_LEGEND_H

#include <cstdint>
#include <string>
#include <vector>

namespace picture {

struct Rgb {
  uint8_t r, g, b;
};

// An RGB picture, 3 bytes a pixel, row 0 at the top.
struct Canvas {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;

  Canvas(int w, int h, Rgb background);
  void set(int x, int y, Rgb c);  // outside: ignored
  void fill(int x, int y, int w, int h, Rgb c);
  // Draws `text` with its top-left corner at (x, y), each font pixel a
  // scale x scale square; lower case is drawn as upper case.
  void text(int x, int y, const std::string &text, int scale, Rgb c);
  // Copies `src` (w x h, 3 bytes a pixel) with its top-left corner at (x, y).
  void paste(int x, int y, int w, int h, const std::vector<uint8_t> &src);
};

// Width and height in pixels of `text` drawn at `scale`.
int text_width(const std::string &text, int scale);
int text_height(int scale);

// What mapdiff's legend says.
struct DiffLegend {
  bool identical = false;   // nothing differs: the legend says so
  uint64_t differing = 0;   // cells that differ (in the overlap and outside it)
};

// The difference picture (width x height, 3 bytes a pixel) with its legend
// below it: the picture is widened (to the right, in the legend's
// background) when the legend needs more room. The colours are map_compare's
// difference colours and A's grey ramp; unknown is carmen::kPictureUnknown.
Canvas with_diff_legend(int width, int height, const std::vector<uint8_t> &rgb, const DiffLegend &legend);

// The legend's colours, for tests and the help text.
constexpr Rgb kHigher{255, 0, 0};      // B higher, |dp| >= 1
constexpr Rgb kLower{0, 0, 255};       // B lower, |dp| >= 1
constexpr Rgb kKnownInA{255, 0, 255};  // known in A only
constexpr Rgb kKnownInB{0, 200, 0};    // known in B only
constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kInk{0, 0, 0};
constexpr Rgb kRule{96, 96, 96};  // the line between picture and legend

}  // namespace picture

#endif  // VASCO_GPU_APP_PICTURE_LEGEND_H
