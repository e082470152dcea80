// needs: cylinder
// The central cylinder: cylinder.glsl's envUv (rule 0 in uParams).
