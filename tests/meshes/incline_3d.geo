// A channel of 2 x 0.5 x 0.5 m tilted by 30 degrees about the y axis: its
// floor (physical surface 1) descends along x. Hexahedra: the floor, a
// transfinite recombined rectangle, tilted and extruded along its normal
// in layers. Make the mesh with
//   gmsh -3 -format msh41 incline_3d.geo -o incline_3d.msh
L = 2;  W = 0.5;  H = 0.5;
Point(1) = {0, 0, 0};  Point(2) = {L, 0, 0};
Point(3) = {L, W, 0};  Point(4) = {0, W, 0};
Line(1) = {1, 2};  Line(2) = {2, 3};  Line(3) = {3, 4};  Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 9;
Transfinite Curve{2, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
Rotate {{0, 1, 0}, {0, 0, 0}, Pi/6} { Surface{1}; }
out[] = Extrude {H*Sin(Pi/6), 0, H*Cos(Pi/6)} {
  Surface{1}; Layers{2}; Recombine;
};
// out[0]: top, out[1]: volume, out[2..5]: the sides on lines 1..4.
Physical Surface(1) = {1};        // floor
Physical Surface(2) = {out[3]};   // lower end (x = L before the tilt)
Physical Surface(3) = {out[0]};   // top
Physical Surface(4) = {out[5]};   // upper end
Physical Surface(5) = {out[2], out[4]}; // sides
Physical Volume(10) = {out[1]};
