// needs: view
// The rectilinear view: view.glsl's envUv (d = 0 in uParams).
