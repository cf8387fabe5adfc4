// The 5 x 7 font and mapdiff's legend (picture_legend.h).
#include "picture_legend.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "carmen_compat/image_io.h"

namespace picture {
namespace {

// Each glyph: 7 rows of 5 pixels, '#' ink, '.' none, top row first.
struct Glyph {
  char c;
  const char *rows;  // 35 characters
};

constexpr Glyph kFont[] = {
    {'A', ".###." "#...#" "#...#" "#####" "#...#" "#...#" "#...#"},
    {'B', "####." "#...#" "#...#" "####." "#...#" "#...#" "####."},
    {'C', ".###." "#...#" "#...." "#...." "#...." "#...#" ".###."},
    {'D', "####." "#...#" "#...#" "#...#" "#...#" "#...#" "####."},
    {'E', "#####" "#...." "#...." "####." "#...." "#...." "#####"},
    {'F', "#####" "#...." "#...." "####." "#...." "#...." "#...."},
    {'G', ".###." "#...#" "#...." "#.###" "#...#" "#...#" ".####"},
    {'H', "#...#" "#...#" "#...#" "#####" "#...#" "#...#" "#...#"},
    {'I', ".###." "..#.." "..#.." "..#.." "..#.." "..#.." ".###."},
    {'J', "..###" "...#." "...#." "...#." "...#." "#..#." ".##.."},
    {'K', "#...#" "#..#." "#.#.." "##..." "#.#.." "#..#." "#...#"},
    {'L', "#...." "#...." "#...." "#...." "#...." "#...." "#####"},
    {'M', "#...#" "##.##" "#.#.#" "#.#.#" "#...#" "#...#" "#...#"},
    {'N', "#...#" "#...#" "##..#" "#.#.#" "#..##" "#...#" "#...#"},
    {'O', ".###." "#...#" "#...#" "#...#" "#...#" "#...#" ".###."},
    {'P', "####." "#...#" "#...#" "####." "#...." "#...." "#...."},
    {'Q', ".###." "#...#" "#...#" "#...#" "#.#.#" "#..#." ".##.#"},
    {'R', "####." "#...#" "#...#" "####." "#.#.." "#..#." "#...#"},
    {'S', ".####" "#...." "#...." ".###." "....#" "....#" "####."},
    {'T', "#####" "..#.." "..#.." "..#.." "..#.." "..#.." "..#.."},
    {'U', "#...#" "#...#" "#...#" "#...#" "#...#" "#...#" ".###."},
    {'V', "#...#" "#...#" "#...#" "#...#" "#...#" ".#.#." "..#.."},
    {'W', "#...#" "#...#" "#...#" "#.#.#" "#.#.#" "#.#.#" ".#.#."},
    {'X', "#...#" "#...#" ".#.#." "..#.." ".#.#." "#...#" "#...#"},
    {'Y', "#...#" "#...#" ".#.#." "..#.." "..#.." "..#.." "..#.."},
    {'Z', "#####" "....#" "...#." "..#.." ".#..." "#...." "#####"},
    {'0', ".###." "#...#" "#..##" "#.#.#" "##..#" "#...#" ".###."},
    {'1', "..#.." ".##.." "..#.." "..#.." "..#.." "..#.." ".###."},
    {'2', ".###." "#...#" "....#" "...#." "..#.." ".#..." "#####"},
    {'3', "#####" "...#." "..#.." "...#." "....#" "#...#" ".###."},
    {'4', "...#." "..##." ".#.#." "#..#." "#####" "...#." "...#."},
    {'5', "#####" "#...." "####." "....#" "....#" "#...#" ".###."},
    {'6', "..##." ".#..." "#...." "####." "#...#" "#...#" ".###."},
    {'7', "#####" "....#" "...#." "..#.." ".#..." ".#..." ".#..."},
    {'8', ".###." "#...#" "#...#" ".###." "#...#" "#...#" ".###."},
    {'9', ".###." "#...#" "#...#" ".####" "....#" "...#." ".##.."},
    {':', "....." ".##.." ".##.." "....." ".##.." ".##.." "....."},
    {'|', "..#.." "..#.." "..#.." "..#.." "..#.." "..#.." "..#.."},
    {'-', "....." "....." "....." "#####" "....." "....." "....."},
    {'.', "....." "....." "....." "....." "....." ".##.." ".##.."},
    {',', "....." "....." "....." "....." ".##.." "..#.." ".#..."},
    {'(', "...#." "..#.." ".#..." ".#..." ".#..." "..#.." "...#."},
    {')', ".#..." "..#.." "...#." "...#." "...#." "..#.." ".#..."},
    {'=', "....." "....." "#####" "....." "#####" "....." "....."},
    {'/', "....." "....#" "...#." "..#.." ".#..." "#...." "....."},
    {'>', ".#..." "..#.." "...#." "....#" "...#." "..#.." ".#..."},
    {'<', "...#." "..#.." ".#..." "#...." ".#..." "..#.." "...#."},
};

constexpr int kGlyphW = 5, kGlyphH = 7, kAdvance = 6;

const char *glyph_rows(char c) {
  if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  for (const Glyph &g : kFont)
    if (g.c == c) return g.rows;
  return nullptr;  // a blank
}

// map_compare's difference colours (carmen_compat/src/map_compare.cc): the
// strength of |dp| on a log scale, 0 at 1e-6, 1 at 1, and the pale channels
// round(170 (1 - strength)) of red (B higher) and blue (B lower).
uint8_t pale_of(double strength) { return static_cast<uint8_t>(std::lround(170.0 * (1.0 - strength))); }

Rgb grey(uint8_t v) { return Rgb{v, v, v}; }

}  // namespace

Canvas::Canvas(int w, int h, Rgb background) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3) {
  fill(0, 0, w, h, background);
}

void Canvas::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  uint8_t *p = rgb.data() + (size_t(y) * size_t(width) + size_t(x)) * 3;
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
}

void Canvas::fill(int x, int y, int w, int h, Rgb c) {
  for (int yy = std::max(0, y); yy < std::min(height, y + h); ++yy)
    for (int xx = std::max(0, x); xx < std::min(width, x + w); ++xx) set(xx, yy, c);
}

void Canvas::text(int x, int y, const std::string &s, int scale, Rgb c) {
  for (size_t i = 0; i < s.size(); ++i) {
    const char *rows = glyph_rows(s[i]);
    if (rows == nullptr) continue;
    const int gx = x + int(i) * kAdvance * scale;
    for (int r = 0; r < kGlyphH; ++r)
      for (int col = 0; col < kGlyphW; ++col)
        if (rows[r * kGlyphW + col] == '#') fill(gx + col * scale, y + r * scale, scale, scale, c);
  }
}

void Canvas::paste(int x, int y, int w, int h, const std::vector<uint8_t> &src) {
  for (int r = 0; r < h; ++r)
    for (int col = 0; col < w; ++col) {
      const uint8_t *p = src.data() + (size_t(r) * size_t(w) + size_t(col)) * 3;
      set(x + col, y + r, Rgb{p[0], p[1], p[2]});
    }
}

int text_width(const std::string &text, int scale) {
  return text.empty() ? 0 : (int(text.size()) * kAdvance - 1) * scale;
}

int text_height(int scale) { return kGlyphH * scale; }

Canvas with_diff_legend(int width, int height, const std::vector<uint8_t> &rgb, const DiffLegend &legend) {
  // Big pictures get bigger letters (one font pixel per 400 picture pixels).
  const int s = std::clamp(width / 400, 1, 4);
  const int margin = 4 * s, line = 11 * s, swatch = 7 * s, ramp = 64 * s, gap = 6 * s;
  const std::string title = legend.identical
                                ? "IDENTICAL: NOTHING DIFFERS"
                                : std::to_string(legend.differing) + (legend.differing == 1 ? " CELL DIFFERS" : " CELLS DIFFER");
  const std::string a_label = "A (SAME IN B): FREE", a_end = "OCCUPIED";
  const std::string dp_label = "|DP|: 1E-6", dp_end = "1 (LOG SCALE)";
  const int widest = std::max({text_width(title, s), swatch + gap + text_width("KNOWN IN A ONLY", s),
                               text_width(a_label, s) + ramp + 2 * gap + text_width(a_end, s),
                               text_width(dp_label, s) + ramp + 2 * gap + text_width(dp_end, s)});
  const int lines = legend.identical ? 3 : 8;  // title, (4 items, |dp| ramp,) A ramp, unknown
  const int w = std::max(width, widest + 2 * margin);
  const int h = height + s + margin + lines * line;
  Canvas c(w, h, kBackground);
  c.paste(0, 0, width, height, rgb);
  if (w > width) c.fill(width, 0, s, height, kRule);  // the picture's right edge, when widened
  c.fill(0, height, w, s, kRule);
  int y = height + s + margin;
  const int text_dy = (swatch - text_height(s)) / 2;
  const auto item = [&](Rgb colour, const std::string &what) {
    c.fill(margin, y, swatch, swatch, colour);
    c.text(margin + swatch + gap, y + text_dy, what, s, kInk);
    y += line;
  };
  c.text(margin, y, title, s, kInk);
  y += line;
  if (!legend.identical) {
    item(kHigher, "B HIGHER");
    item(kLower, "B LOWER");
    item(kKnownInA, "KNOWN IN A ONLY");
    item(kKnownInB, "KNOWN IN B ONLY");
    // |dp| from 1e-6 (pale) to 1 (full), linear in log10: red above, blue below.
    int x = margin;
    c.text(x, y, dp_label, s, kInk);
    x += text_width(dp_label, s) + gap;
    for (int i = 0; i < ramp; ++i) {
      const uint8_t pale = pale_of(double(i) / double(ramp - 1));
      c.fill(x + i, y, 1, swatch / 2, Rgb{255, pale, pale});
      c.fill(x + i, y + swatch / 2, 1, swatch - swatch / 2, Rgb{pale, pale, 255});
    }
    c.text(x + ramp + gap, y, dp_end, s, kInk);
    y += line;
  }
  // A's grey where B agrees: white p = 0 (free) to black p = 1 (occupied).
  int x = margin;
  c.text(x, y, a_label, s, kInk);
  x += text_width(a_label, s) + gap;
  for (int i = 0; i < ramp; ++i) c.fill(x + i, y, 1, swatch, grey(carmen::png_pixel(float(i) / float(ramp - 1))));
  c.text(x + ramp + gap, y, a_end, s, kInk);
  y += line;
  item(Rgb{carmen::kPictureUnknown.r, carmen::kPictureUnknown.g, carmen::kPictureUnknown.b}, "UNKNOWN IN BOTH");
  return c;
}

}  // namespace picture
