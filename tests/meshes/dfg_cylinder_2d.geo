// The channel of the DFG benchmark "flow around a cylinder" (Schaefer &
// Turek 1996): [0, 2.2] x [0, 0.41], a cylinder of radius 0.05 centred at
// (0.2, 0.2). Quadrilaterals in 12 transfinite blocks: an O-grid of four
// between the cylinder and the square [0.1, 0.3]^2, eight around it.
// Physical lines: 1 inflow (x = 0), 2 outflow (x = 2.2), 3 channel walls,
// 4 the cylinder. Make the mesh with
//   gmsh -2 -format msh41 dfg_cylinder_2d.geo -o dfg_cylinder_2d.msh
r = 0.05;  s = Sqrt(2)/2;
nl = 2;  nb = 4;  nr = 2;  nx = 19;  ny1 = 2;  ny3 = 2;
Point(1) = {0, 0, 0};      Point(2) = {0.1, 0, 0};
Point(3) = {0.3, 0, 0};    Point(4) = {2.2, 0, 0};
Point(5) = {0, 0.1, 0};    Point(6) = {0.1, 0.1, 0};
Point(7) = {0.3, 0.1, 0};  Point(8) = {2.2, 0.1, 0};
Point(9) = {0, 0.3, 0};    Point(10) = {0.1, 0.3, 0};
Point(11) = {0.3, 0.3, 0}; Point(12) = {2.2, 0.3, 0};
Point(13) = {0, 0.41, 0};  Point(14) = {0.1, 0.41, 0};
Point(15) = {0.3, 0.41, 0}; Point(16) = {2.2, 0.41, 0};
Point(17) = {0.2, 0.2, 0};
Point(18) = {0.2 - r*s, 0.2 - r*s, 0};  Point(19) = {0.2 + r*s, 0.2 - r*s, 0};
Point(20) = {0.2 + r*s, 0.2 + r*s, 0};  Point(21) = {0.2 - r*s, 0.2 + r*s, 0};
Line(1) = {1, 2};   Line(2) = {2, 3};   Line(3) = {3, 4};
Line(4) = {5, 6};   Line(5) = {6, 7};   Line(6) = {7, 8};
Line(7) = {9, 10};  Line(8) = {10, 11}; Line(9) = {11, 12};
Line(10) = {13, 14}; Line(11) = {14, 15}; Line(12) = {15, 16};
Line(13) = {1, 5};  Line(14) = {5, 9};  Line(15) = {9, 13};
Line(16) = {2, 6};  Line(17) = {6, 10}; Line(18) = {10, 14};
Line(19) = {3, 7};  Line(20) = {7, 11}; Line(21) = {11, 15};
Line(22) = {4, 8};  Line(23) = {8, 12}; Line(24) = {12, 16};
Circle(25) = {18, 17, 19};  Circle(26) = {19, 17, 20};
Circle(27) = {20, 17, 21};  Circle(28) = {21, 17, 18};
Line(29) = {6, 18}; Line(30) = {7, 19}; Line(31) = {11, 20}; Line(32) = {10, 21};
Curve Loop(1) = {1, 16, -4, -13};   Curve Loop(2) = {4, 17, -7, -14};
Curve Loop(3) = {7, 18, -10, -15};  Curve Loop(4) = {2, 19, -5, -16};
Curve Loop(5) = {8, 21, -11, -18};  Curve Loop(6) = {3, 22, -6, -19};
Curve Loop(7) = {6, 23, -9, -20};   Curve Loop(8) = {9, 24, -12, -21};
Curve Loop(9) = {5, 30, -25, -29};  Curve Loop(10) = {20, 31, -26, -30};
Curve Loop(11) = {-8, 32, -27, -31}; Curve Loop(12) = {-17, 29, -28, -32};
For k In {1:12}
  Plane Surface(k) = {k};
EndFor
Transfinite Curve{1, 4, 7, 10} = nl + 1;
Transfinite Curve{2, 5, 8, 11, 17, 20, 25, 26, 27, 28, 14, 23} = nb + 1;
Transfinite Curve{3, 6, 9, 12} = nx + 1;
Transfinite Curve{13, 16, 19, 22} = ny1 + 1;
Transfinite Curve{15, 18, 21, 24} = ny3 + 1;
Transfinite Curve{29, 30, 31, 32} = nr + 1;
Transfinite Surface{1:12};
Recombine Surface{1:12};
Physical Curve(1) = {13, 14, 15};
Physical Curve(2) = {22, 23, 24};
Physical Curve(3) = {1, 2, 3, 10, 11, 12};
Physical Curve(4) = {25, 26, 27, 28};
Physical Surface(10) = {1:12};
