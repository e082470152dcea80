// needs: fisheye
// The fisheye: fisheye.glsl's envUv (the lens and field of view in uParams).
