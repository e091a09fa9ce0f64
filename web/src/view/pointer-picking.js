// Pointer interaction for vertex picking on the viewer's canvas: hovering reports the vertex
// under the pointer (at most once per animation frame, and not while a button is held, i.e.
// while the user orbits), leaving the canvas reports null, and a click (press and release
// without moving more than a few pixels, so an orbit drag is not a click) reports a pick.
// Returns a function that detaches the listeners.
const clickSlopPx = 4;

export function attachPointerPicking(viewer, { onHover = () => {}, onClick = () => {} }) {
  const canvas = viewer.renderer.domElement;
  let pending = null;  // the latest pointer position waiting for the next frame
  let frame = 0;
  let down = null;     // where the primary button went down

  const hoverAt = () => {
    frame = 0;
    if (!pending) return;
    const { x, y } = pending;
    pending = null;
    onHover(viewer.pickAt(x, y));
  };

  const listeners = {
    pointermove(e) {
      if (e.buttons !== 0) return;
      pending = { x: e.clientX, y: e.clientY };
      if (!frame) frame = requestAnimationFrame(hoverAt);
    },
    pointerleave() {
      pending = null;
      if (frame) cancelAnimationFrame(frame);
      frame = 0;
      onHover(null);
    },
    pointerdown(e) {
      down = e.button === 0 ? { x: e.clientX, y: e.clientY } : null;
    },
    pointerup(e) {
      if (!down || e.button !== 0) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      down = null;
      if (moved <= clickSlopPx) onClick(viewer.pickAt(e.clientX, e.clientY));
    },
  };
  for (const [type, fn] of Object.entries(listeners)) canvas.addEventListener(type, fn);
  return () => {
    for (const [type, fn] of Object.entries(listeners)) canvas.removeEventListener(type, fn);
    if (frame) cancelAnimationFrame(frame);
  };
}
