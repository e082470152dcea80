// needs: fisheye
// The angular map: fisheye.glsl's envUv (the equidistant lens to theta_max = pi, in uParams).
