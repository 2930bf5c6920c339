// Exported by abcube from hidden_point.json
// z is mirrored: POV-Ray is left-handed (abcube docs/design/pov-export.md).
#version 3.7;
global_settings {
  assumed_gamma 1.0
  max_trace_level 3
  adc_bailout 0
  ambient_light rgb <0.10000000000000001, 0.10000000000000001, 0.10000000000000001>
}
background { rgb <0, 0, 0> }
camera {
  perspective
  location <0, 1.2, -5>
  direction <0, 0, 0.94036323267316602>
  right x*1.3333333333333333
  up y
  sky <0, 1, -0>
  look_at <0.20000000000000001, 1.1000000000000001, -0>
}
light_source { <1, 5, -6> color rgb <1, 1, 1> shadowless }
// material 0: white_mirror
#declare ABCUBE_M0 = material {
  texture {
    pigment { rgbt <1, 1, 1, 0> }
    finish { ambient 0.10000000000000001 diffuse 0.10000000000000001 specular 0 reflection { 0.90000000000000002 } }
  }
}
// material 1: red
#declare ABCUBE_M1 = material {
  texture {
    pigment { rgbt <0.90000000000000002, 0.10000000000000001, 0.10000000000000001, 0> }
    finish { ambient 1 diffuse 1 specular 0 reflection { 0 } }
  }
}
// material 2: green
#declare ABCUBE_M2 = material {
  texture {
    pigment { rgbt <0.10000000000000001, 0.80000000000000004, 0.20000000000000001, 0> }
    finish { ambient 1 diffuse 1 specular 0 reflection { 0 } }
  }
}
// object 0 (objects[0])
mesh2 {
  vertex_vectors { 3,
    <0.75, -0.400000006, 2.54999995>,
    <3.25, -0.400000006, -1.54999995>,
    <2, 3.4000001, 0.5>
  }
  normal_vectors { 3,
    <-0.853796184, 0, -0.520607412>,
    <-0.853796184, 0, -0.520607412>,
    <-0.853796184, 0, -0.520607412>
  }
  face_indices { 1,
    <0, 1, 2>
  }
  material { ABCUBE_M0 }
}
// object 1 (objects[1])
mesh2 {
  vertex_vectors { 3,
    <-1.13999999, 0.300000012, -1.97000003>,
    <-0.460000008, 0.300000012, -1.23000002>,
    <-1.13999999, 1.5, -1.97000003>
  }
  normal_vectors { 3,
    <0.736327529, -0, -0.676625252>,
    <0.736327529, -0, -0.676625252>,
    <0.736327529, -0, -0.676625252>
  }
  face_indices { 1,
    <0, 1, 2>
  }
  material { ABCUBE_M1 }
}
// object 2 (objects[2])
mesh2 {
  vertex_vectors { 3,
    <-2.5, 0, -0.949999988>,
    <-0.699999988, 0, 0.949999988>,
    <-1.60000002, 2.4000001, -0>
  }
  normal_vectors { 3,
    <0.725952685, 9.01461483e-09, -0.687744677>,
    <0.725952685, 9.01461483e-09, -0.687744677>,
    <0.725952685, 9.01461483e-09, -0.687744677>
  }
  face_indices { 1,
    <0, 1, 2>
  }
  material { ABCUBE_M2 }
}
