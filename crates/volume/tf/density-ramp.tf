# bnsview transfer function: one control point per line, `value r g b a`.
# value: position in the normalised density range [0, 1] (0 = range low, 1 = range high)
# r g b: emitted colour in [0, 1];  a: opacity per voxel of path length in [0, 1]
# Values must not decrease; entries between points are interpolated linearly.
0.00   0.10 0.20 0.60   0.00
0.15   0.10 0.20 0.60   0.00   # empty space and Gaussian tails: transparent
0.35   0.20 0.55 0.85   0.04
0.60   0.85 0.85 0.80   0.12
0.85   0.95 0.55 0.25   0.25
1.00   0.80 0.10 0.10   0.35   # atom cores
