// needs: cylinder
// Lambert's cylindrical equal-area: cylinder.glsl's envUv (rule 1 in uParams).
