// The web player's heads-up text (player.js's "hud" room, issue 43): what the desktop HUD (ui/hud.cpp)
// says, as the same words, from the player's state. Pure: player.js writes it into the page.
import { timeText } from "./legend.js";
import { latticeNode, viewDirection, lookText, positionOf } from "./look.js";

/// The HUD's lines for `frame` of state S (options: the page's URL options).
export function hudText(S, frame, options) {
  const db = S.db, c = S.camera, task = db.tasks[S.task];
  const last = S.switches.findLast((w) => w.ms !== null);
  const axes = task.axes.map((a) => `${a.axis}=${db.axes.find((x) => x.name === a.axis)?.values[a.index]}`).join(" ");
  const active = db.axes[S.axis] && !S.rig.walkable ? `PgUp/PgDn: ${db.axes[S.axis].name}` : "";
  // Frames from 0 and "x speed, reverse, once" as the desktop HUD (ui/hud.cpp); tasks from 1 as the digit keys.
  const speed = Number(S.speed.toPrecision(2));
  let where;
  if (!S.cams) where = `camera ${c}  (loading the camera table…)`;
  else if (S.rig.lattice || S.rig.path) {
    const p = positionOf(S.cams, c), v = viewDirection(S.cams, c, S.look);
    const node = S.rig.lattice ? `  lattice (${latticeNode(S.rig.lattice, c).join(", ")}) of ${S.rig.lattice.join("x")}` : "";
    const heading = ((Math.atan2(v[1], v[0]) * 180) / Math.PI + 360) % 360;  // from north (x) towards east (y)
    where = `camera ${c}${node}  at (${p.map((x) => Number(x.toPrecision(4))).join(", ")})${db.domain_units ? " " + db.domain_units : ""}  heading ${Math.round(heading) % 360}°`;
  } else {
    // The shell only where there are several, as the desktop HUD.
    S.cams.shellCount ??= new Set(S.cams.shell).size;
    // Whole signed degrees, as the desktop HUD writes them (ui/hud_text's signed_degrees): "lat +36°".
    const deg = (d) => { const r = Math.round(d); return r === 0 ? "0°" : `${r > 0 ? "+" : ""}${r}°`; };
    where = `camera ${c}  lat ${deg(S.cams.lat_deg[c])}  lon ${deg(S.cams.lon_deg[c])}` +
      (S.cams.shellCount > 1 ? `  shell ${S.cams.shell[c]}` : "");
  }
  const text =
    `${timeText(db, db.times[frame] ?? frame)}  frame ${frame} of ${db.frames}  ${S.playing ? "playing" : "paused"} x${speed}${S.dir < 0 ? " reverse" : ""}${S.loop ? "" : " once"}\n` +
    (db.frames_verified === "none" ? "frames unverified (written before frame checks)\n" : "") +
    where + "\n" +
    (S.rig.equirect ? (S.rig.walkable ? "" : "360 view  ") + lookText(S.look) + "\n" : "") +
    `task ${S.task + 1} of ${db.tasks.length}: "${task.name}" ${axes}  ${active}\n` +
    `last switch ${last ? last.ms.toFixed(1) + " ms" + (last.hit ? " (next frame)" : " (waited for a decode)") : "—"} (input event to screen)` +
    `${S.rig.equirect ? "" : "  zoom " + S.zoom.toFixed(2)}${options.prefetch ? "" : "  prefetch off"}`;
  return text;
}
