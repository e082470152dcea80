// needs: view
// The Pannini view: view.glsl's envUv (its d in uParams).
