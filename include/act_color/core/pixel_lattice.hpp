#pragma once

namespace act_color {
namespace core {

// Every s-th pixel of a row-major image w pixels wide, from any start, is a lattice of the image
// plane: the pixels (u, v) with u + w v = start (mod s). Its shape depends on w mod s. At s = 400
// and w = 800 it is two columns of the image (and 6 at 480 px, 8 at 640): a frame's samples then
// miss whatever lies between them.

// The length in pixels of the lattice's shortest nonzero vector: the spacing of its samples along
// their densest direction (about 1.07 sqrt(s) for the best lattices, 1 for columns).
double latticeSpacing(int stride, int width);

// The smallest stride from n to n + max(3, n / 8) (at most n + 64) whose lattice is spread nearly
// as well as the best in that range (spacing over sqrt(stride)): about as many samples as every
// n-th pixel, over the whole image.
int latticeStride(int n, int width);

}  // namespace core
}  // namespace act_color
