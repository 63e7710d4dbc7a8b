// A channel of 2 x 0.5 m tilted by 30 degrees: its floor (physical line 1)
// descends to the right. Quadrilaterals: a transfinite, recombined
// rectangle, rotated after meshing. Make the mesh with
//   gmsh -2 -format msh41 incline_2d.geo -o incline_2d.msh
L = 2;  H = 0.5;
Point(1) = {0, 0, 0};  Point(2) = {L, 0, 0};
Point(3) = {L, H, 0};  Point(4) = {0, H, 0};
Line(1) = {1, 2};  Line(2) = {2, 3};  Line(3) = {3, 4};  Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 17;
Transfinite Curve{2, 4} = 5;
Transfinite Surface{1};
Recombine Surface{1};
Rotate {{0, 0, 1}, {0, 0, 0}, -Pi/6} { Surface{1}; }
Physical Curve(1) = {1};   // floor
Physical Curve(2) = {2};   // lower end
Physical Curve(3) = {3};   // top
Physical Curve(4) = {4};   // upper end
Physical Surface(10) = {1};
