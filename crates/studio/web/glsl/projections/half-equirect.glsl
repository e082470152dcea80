// needs: cylinder
// The half equirectangular (VR180): cylinder.glsl's envUv (rule 2 in uParams).
