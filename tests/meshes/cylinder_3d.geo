// A vertical cylinder of radius 0.5 and height 1, axis the z axis: the
// O-grid of disc_2d.geo (a square core and four blocks, 20 quadrilaterals
// per layer) extruded in 4 layers of hexahedra. Physical surfaces: 1 the
// curved side, 2 the floor (z = 0), 3 the top; physical volume 10.
// Make the mesh with
//   gmsh -3 -format msh41 cylinder_3d.geo -o cylinder_3d.msh
R = 0.5;  a = 0.2;  s = Sqrt(2)/2;  H = 1;
n = 2;  nr = 2;
Point(1) = {0, 0, 0};
Point(2) = {-a, -a, 0};  Point(3) = {a, -a, 0};
Point(4) = {a, a, 0};    Point(5) = {-a, a, 0};
Point(6) = {-R*s, -R*s, 0};  Point(7) = {R*s, -R*s, 0};
Point(8) = {R*s, R*s, 0};    Point(9) = {-R*s, R*s, 0};
Line(1) = {2, 3};  Line(2) = {3, 4};  Line(3) = {4, 5};  Line(4) = {5, 2};
Circle(5) = {6, 1, 7};  Circle(6) = {7, 1, 8};
Circle(7) = {8, 1, 9};  Circle(8) = {9, 1, 6};
Line(9) = {2, 6};  Line(10) = {3, 7};  Line(11) = {4, 8};  Line(12) = {5, 9};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {1, 10, -5, -9};
Curve Loop(3) = {2, 11, -6, -10};
Curve Loop(4) = {3, 12, -7, -11};
Curve Loop(5) = {4, 9, -8, -12};
For k In {1:5}
  Plane Surface(k) = {k};
EndFor
Transfinite Curve{1:8} = n + 1;
Transfinite Curve{9:12} = nr + 1;
Transfinite Surface{1:5};
Recombine Surface{1:5};
side[] = {};  top[] = {};  vol[] = {};
For k In {1:5}
  out[] = Extrude {0, 0, H} { Surface{k}; Layers{4}; Recombine; };
  top[] += out[0];  vol[] += out[1];
  If (k > 1)
    side[] += out[4];  // the face on the circle (the loop's third curve)
  EndIf
EndFor
Physical Surface(1) = {side[]};
Physical Surface(2) = {1:5};
Physical Surface(3) = {top[]};
Physical Volume(10) = {vol[]};
