// The analysis panel: the projection the viewport shows, measured and drawn on the server by
// the analysis crate exactly as `mirrorball analyze --projection P --size N` measures and
// draws it (`GET /api/analysis`, crates/studio/src/analysis.rs): its solid-angle and
// anisotropy heat maps and Zimmons' 1-D profile as the report's own SVG figures, its
// numbers, and the share of its texels the camera's frustum sees against the frustum's share
// of the sphere (Greene §9). Opened by the header's button or `analysis=1` in the URL (the
// edge measured: `analysis-size=N`, else the report's default budget of 6×512² texels);
// measured again when the projection changes while it is open.

/** The panel's rows: [label, value of the payload `a`]. */
function rows(a) {
  const s = a.entry.stats;
  const f = a.frustum;
  const pct = (x) => `${(100 * x).toFixed(2)}%`;
  const out = [
    ['measured at', `${s.layers}×${s.width}×${s.height} texels (edge ${a.size})`],
    ['solid angle per texel, max/min', `${s.full.ratio.toFixed(4)} (full texels); ${s.with_partial.ratio.toFixed(4)} with the rim's`],
    ['texel solid angles sum to', `${s.solid_angle_sum.toFixed(6)} sr of ${s.covered_solid_angle.toFixed(6)} covered`],
    ['anisotropy', `max ${s.anisotropy_max.value.toFixed(4)}, mean ${s.anisotropy_mean.toFixed(4)} (${s.anisotropy_mean_sphere.toFixed(4)} over the sphere)`],
    ['used area', pct(s.used_area_fraction)],
    ['texels looking front / back / unused', `${pct(s.front_share)} / ${pct(s.back_share)} / ${pct(s.unused_share)}`],
  ];
  if (s.crossover) out.push(['front/back crossover', `radius ${s.crossover.radius_uv.toFixed(4)} in uv (${s.crossover.radius_texels.toFixed(1)} texels)${s.crossover.at_rim ? ', at the rim' : ''}`]);
  const walks = a.entry.profile.walks.map((w) => `${w.name} ${w.ratio.toFixed(3)}`).join(', ');
  out.push(["Zimmons' 1-D max/min", walks]);
  if (f) {
    out.push([
      `the camera's frustum (${f.horizontal_fov_deg.toFixed(1)}°×${f.vertical_fov_deg.toFixed(1)}°)`,
      `sees ${pct(f.texel_share)} of the texels (${f.texels} of ${f.of}) and ${pct(f.sphere_share)} of the sphere`,
    ]);
  }
  return out;
}

/** Plugs the panel into the studio page's handle (studio.js); returns its own handle. */
export function attach(studio) {
  const { G, view } = studio;
  const params = new URLSearchParams(location.search);
  const panel = document.getElementById('analysis');
  const button = document.getElementById('analyse');
  const an = { open: !studio.embed && params.get('analysis') === '1', size: params.get('analysis-size'), last: null, pending: null };

  function writeUrl() {
    const p = new URLSearchParams(location.search);
    if (an.open) p.set('analysis', '1');
    else p.delete('analysis');
    history.replaceState(null, '', `${location.pathname}?${p}`);
  }

  /** The query for the camera as the viewport draws it now. */
  function cameraQuery() {
    const c = view.state.scene.camera;
    if (c.fov === null) return '';
    const v = studio.camera().view;
    const forward = [-v[2], -v[6], -v[10]];
    const up = [v[1], v[5], v[9]];
    return `&fov=${c.fov}&aspect=${c.width / c.height}&forward=${forward.join(',')}&up=${up.join(',')}`;
  }

  /** Measures the projection shown now and fills the panel; resolves to the payload. */
  an.measure = async () => {
    an.open = true;
    writeUrl();
    panel.hidden = false;
    const status = document.createElement('p');
    status.className = 'note';
    status.textContent = `measuring the ${view.projection === 'native' ? 'loaded' : view.projection} projection on the server…`;
    panel.replaceChildren(status);
    let q = `projection=${encodeURIComponent(view.projection)}${cameraQuery()}`;
    if (an.size) q += `&size=${encodeURIComponent(an.size)}`;
    const run = (async () => {
      const a = await (await G.api(`/api/analysis?${q}`)).json();
      const title = document.createElement('h3');
      title.textContent = `Analysis: ${a.projection}`;
      const table = document.createElement('table');
      for (const [k, v] of rows(a)) {
        const tr = table.insertRow();
        tr.insertCell().textContent = k;
        tr.insertCell().textContent = v;
      }
      const figures = a.figures.map((f) => {
        const fig = document.createElement('figure');
        fig.id = f.id;
        const img = document.createElement('img');
        img.alt = f.title;
        img.src = URL.createObjectURL(new Blob([f.svg], { type: 'image/svg+xml' }));
        const cap = document.createElement('figcaption');
        cap.className = 'note';
        cap.textContent = f.caption;
        fig.append(img, cap);
        return fig;
      });
      panel.replaceChildren(title, table, ...figures);
      await Promise.all(figures.map((f) => f.querySelector('img').decode()));
      an.last = a;
      return a;
    })();
    an.pending = run;
    try {
      return await run;
    } catch (e) {
      status.className = 'error';
      status.textContent = `the analysis failed: ${e.message}`;
      throw e;
    }
  };

  an.close = () => {
    an.open = false;
    writeUrl();
    panel.hidden = true;
  };

  button.addEventListener('click', () => (an.open ? an.close() : an.measure().catch(() => {})));
  document.getElementById('projection').addEventListener('change', () => {
    // studio.js loads the new map first; measure what it then shows.
    if (an.open) setTimeout(() => studio.ready.then(() => an.measure()).catch(() => {}), 0);
  });
  an.ready = studio.ready.then(() => (an.open ? an.measure() : null));
  return an;
}
