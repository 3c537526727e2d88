// The page of `flexdyn view` (crates/sinks/src/web): a client of the Foxglove WebSocket protocol
// (`foxglove.websocket.v1`) in plain JavaScript, connected back to the port that served it. It
// subscribes to the decoded JSON channels of one vehicle and draws them on canvases: the
// spacecraft in its body frame B, scrolling plots, the run state, the eclipse, the faults and
// the flight code's mode and last event.
// A live run and a replay (`flexdyn view --file`) are the same stream, so they look the same.
//
// Channels (crates/sinks/src/view.rs, all "json"): /flexdyn/<sc>/tlm/state (StateMsg),
// /tlm/env (EnvironmentMsg), /tlm/fault (FaultEventMsg), /status (StatusMsg), and for the
// geometry of the served configuration /scene (foxglove.SceneUpdate: cubes per frame, spheres
// for the tanks) with /tf (foxglove.FrameTransforms: the frames of the pairs' and chains' panels
// at their hinge angles) and /actuators (per state: the propellant left in each tank, a sphere;
// its arrows are not drawn here), and the flight
// code's telemetry /fsw/<stream> (FswMsg, which a live server passes on once accepted) with the
// names behind its indices /fsw_streams (the served configuration's [[fsw_streams]]).
//
// URL parameters: ?sc=ID (the vehicle; default the first one advertised), ?window=S (the plots'
// span, default 60 s), ?hold=MS (see below).
'use strict';
(function () {
  const params = new URLSearchParams(location.search);
  const WINDOW_S = Number(params.get('window')) > 0 ? Number(params.get('window')) : 60;
  const WANT_SC = params.get('sc');
  // ?hold=MS: keep the load event pending for MS ms of real time (an image the server answers
  // that late), so a headless browser's --dump-dom or --screenshot shows MS ms of the stream.
  const HOLD_MS = Number(params.get('hold'));
  if (HOLD_MS > 0) {
    const img = document.createElement('img');
    img.hidden = true;
    img.alt = '';
    img.src = '/hold?ms=' + Math.round(HOLD_MS);
    document.body.appendChild(img);
  }
  const $ = (id) => document.getElementById(id);
  const dec = new TextDecoder();
  const COLORS = ['#ff6b6b', '#51cf66', '#4dabf7', '#ffd43b', '#cc5de8', '#ff922b', '#20c997', '#f783ac'];
  const FAULT_MODES = ['stuck_current', 'stuck_value', 'bias_step', 'bias_ramp', 'scale', 'noise',
    'spikes', 'dropout', 'validity_off', 'friction_scale', 'torque_limit', 'seized',
    'command_ignored', 'stuck_on', 'stuck_off', 'thrust_scale', 'dead', 'dipole_scale', 'dropped',
    'delayed', 'corrupted'];
  const ECLIPSE = ['sunlit', 'penumbra', 'umbra'];

  // ---- Time series over the last WINDOW_S seconds -------------------------------------------
  class Series {
    constructor() { this.clear(); }
    clear() { this.t = []; this.v = []; this.start = 0; this.labels = []; }
    push(t, values, labels) {
      const n = this.t.length;
      if ((n > this.start && t < this.t[n - 1]) || labels.join() !== this.labels.join()) {
        this.clear(); // a seek back, a restart, or another set of lines
        this.labels = labels.slice();
      }
      this.t.push(t);
      this.v.push(values);
      const cut = t - WINDOW_S;
      while (this.start < this.t.length && this.t[this.start] < cut) this.start++;
      if (this.start > 4096 && this.start > this.t.length / 2) {
        this.t = this.t.slice(this.start);
        this.v = this.v.slice(this.start);
        this.start = 0;
      }
    }
    get length() { return this.t.length - this.start; }
    last() { return this.length ? this.t[this.t.length - 1] : 0; }
  }
  const series = { sigma: new Series(), omega: new Series(), wheels: new Series(), hinges: new Series() };

  // ---- What the stream said --------------------------------------------------------------------
  const view = {
    sc: WANT_SC, vehicles: new Set(), state: null, env: null, status: null,
    faults: new Map(), scene: null, tf: new Map(), actuators: null, messages: 0,
    fsw: new Map(), fswStreams: new Map(), // stream → {mode, event, eventT}; stream → declaration
    playback: null, dataStart: null, dataEnd: null, playbackState: null,
  };
  let ws = null;
  let channels = new Map(); // channel id → channel
  let subscribed = new Map(); // channel id → subscription id
  let subKinds = new Map(); // subscription id → kind
  let nextSub = 1;
  let headerDirty = true;
  let sceneDirty = true;
  let plotsDirty = true;
  let requestNo = 0;

  function kindOf(topic) {
    const m = /^\/flexdyn\/([^/]+)\/(tlm\/state|tlm\/env|tlm\/fault|status|scene|actuators|tf|fsw_streams|fsw\/[^/]+)$/.exec(topic);
    if (!m) return null;
    // The flight code's telemetry: the kind `fsw` and the stream's name.
    if (m[2].startsWith('fsw/')) return { sc: m[1], kind: 'fsw', stream: m[2].slice(4) };
    return { sc: m[1], kind: m[2].replace('tlm/', '') };
  }

  function subscribeWanted() {
    if (!ws || ws.readyState !== WebSocket.OPEN || !view.sc) return;
    const list = [];
    for (const [id, ch] of channels) {
      const k = kindOf(ch.topic);
      if (!k || k.sc !== view.sc || subscribed.has(id) || ch.encoding !== 'json') continue;
      const sub = nextSub++;
      subscribed.set(id, sub);
      subKinds.set(sub, k.kind === 'fsw' ? 'fsw/' + k.stream : k.kind);
      list.push({ id: sub, channelId: id });
    }
    if (list.length) ws.send(JSON.stringify({ op: 'subscribe', subscriptions: list }));
  }

  function onAdvertise(list) {
    for (const ch of list) {
      channels.set(ch.id, ch);
      const k = kindOf(ch.topic);
      if (k && k.kind === 'state') {
        view.vehicles.add(k.sc);
        if (!view.sc) view.sc = k.sc;
        headerDirty = true;
      }
    }
    subscribeWanted();
  }

  function onUnadvertise(ids) {
    for (const id of ids) {
      channels.delete(id);
      const sub = subscribed.get(id);
      if (sub !== undefined) subKinds.delete(sub);
      subscribed.delete(id);
    }
  }

  // ---- Playback control (a replay: `flexdyn view --file`) ------------------------------------
  const nsOf = (t) => (t ? t.sec * 1e9 + t.nsec : null);

  function playbackRequest(play, seekNs) {
    if (!ws || ws.readyState !== WebSocket.OPEN) return;
    const id = new TextEncoder().encode('web-' + (++requestNo));
    const hasSeek = seekNs !== null && seekNs !== undefined;
    // The seek time's 8 bytes are always there (0 without a seek).
    const buf = new ArrayBuffer(1 + 1 + 4 + 1 + 8 + 4 + id.length);
    const dv = new DataView(buf);
    let o = 0;
    dv.setUint8(o++, 3); // playbackControlRequest
    dv.setUint8(o++, play ? 0 : 1);
    dv.setFloat32(o, 0, true); o += 4; // 0: keep the current speed
    dv.setUint8(o++, hasSeek ? 1 : 0);
    if (hasSeek) {
      dv.setUint32(o, seekNs % 4294967296, true);
      dv.setUint32(o + 4, Math.floor(seekNs / 4294967296), true);
    }
    o += 8;
    dv.setUint32(o, id.length, true); o += 4;
    new Uint8Array(buf, o).set(id);
    ws.send(buf);
    return 'web-' + requestNo;
  }

  let helloId = null;
  function onPlaybackState(dv) {
    const status = dv.getUint8(1);
    const current = dv.getUint32(2, true) + dv.getUint32(6, true) * 4294967296;
    const idLen = dv.byteLength >= 19 ? dv.getUint32(15, true) : 0;
    const reqId = idLen ? dec.decode(new Uint8Array(dv.buffer, 19, idLen)) : null;
    view.playbackState = ['playing', 'paused', 'buffering', 'ended'][status] || String(status);
    // Opened after the replay ended: play it again from its start.
    if (reqId && reqId === helloId && view.dataEnd !== null && current >= view.dataEnd) {
      playbackRequest(true, view.dataStart);
      view.playbackState = 'restarted';
    }
    headerDirty = true;
  }

  // ---- Messages ---------------------------------------------------------------------------------
  function onMessage(kind, msg) {
    view.messages++;
    if (kind === 'state') {
      view.state = msg;
      const t = msg.header.sim_time_ns / 1e9;
      const s = msg.sigma_bn;
      series.sigma.push(t, [Math.hypot(s[0], s[1], s[2]), s[0], s[1], s[2]], ['|σ|', 'σ1', 'σ2', 'σ3']);
      const w = msg.omega_bn_b_rad_s;
      series.omega.push(t, [w[0], w[1], w[2]], ['ωx', 'ωy', 'ωz']);
      const wheels = [], wl = [], hinges = [], hl = [];
      let p = 0, r = 0;
      for (const e of msg.effectors || []) {
        if (e.kind === 1) {
          p++;
          hinges.push(e.states[0] * 180 / Math.PI, e.states[2] * 180 / Math.PI);
          hl.push('θ1 #' + p, 'θ2 #' + p);
        } else if (e.kind === 2) {
          r++;
          wheels.push(e.states[0]);
          wl.push('Ω #' + r);
        }
      }
      series.wheels.push(t, wheels, wl);
      series.hinges.push(t, hinges, hl);
      sceneDirty = plotsDirty = true;
    } else if (kind === 'env') {
      view.env = msg;
      sceneDirty = true;
    } else if (kind === 'status') {
      view.status = msg;
    } else if (kind === 'fault') {
      view.faults.set(msg.fault_index, msg);
    } else if (kind === 'scene') {
      view.scene = msg;
      sceneDirty = true;
    } else if (kind === 'actuators') {
      view.actuators = msg;
      sceneDirty = true;
    } else if (kind === 'fsw_streams') {
      for (const d of msg.streams || []) view.fswStreams.set(d.name, d);
    } else if (kind.startsWith('fsw/')) {
      // FswMsg: flags bit 0 says `mode` is set; `events` holds `event_count` indices.
      const stream = kind.slice(4);
      const seen = view.fsw.get(stream) || { mode: null, event: null, eventT: null };
      if (msg.flags & 1) seen.mode = msg.mode;
      if (msg.event_count > 0) {
        seen.event = msg.events[msg.event_count - 1];
        seen.eventT = msg.header.sim_time_ns / 1e9;
      }
      view.fsw.set(stream, seen);
    } else if (kind === 'tf') {
      for (const tr of msg.transforms || []) view.tf.set(tr.child_frame_id, tr);
      sceneDirty = true;
    }
    headerDirty = true;
  }

  function onBinary(buf) {
    const dv = new DataView(buf);
    const op = dv.getUint8(0);
    if (op === 1) { // messageData: u32 subscription, u64 time, payload
      const kind = subKinds.get(dv.getUint32(1, true));
      if (!kind) return;
      let msg;
      try { msg = JSON.parse(dec.decode(new Uint8Array(buf, 13))); } catch (e) { return; }
      onMessage(kind, msg);
    } else if (op === 5) {
      onPlaybackState(dv);
    }
  }

  function onText(text) {
    let m;
    try { m = JSON.parse(text); } catch (e) { return; }
    if (m.op === 'serverInfo') {
      const caps = m.capabilities || [];
      view.dataStart = nsOf(m.dataStartTime);
      view.dataEnd = nsOf(m.dataEndTime);
      view.playback = caps.includes('playbackControl');
      $('playback').hidden = !view.playback;
      log('connected to ' + (m.name || 'flexdyn') + (view.playback ? ' (replay of a recording)' : ' (live)'));
      if (view.playback) helloId = playbackRequest(true, null);
    } else if (m.op === 'advertise') {
      onAdvertise(m.channels || []);
    } else if (m.op === 'unadvertise') {
      onUnadvertise(m.channelIds || []);
    } else if (m.op === 'status') {
      log('server: ' + m.message);
    }
  }

  function log(text) { $('log').textContent = text; }

  function connect() {
    const url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/';
    channels = new Map(); subscribed = new Map(); subKinds = new Map(); nextSub = 1;
    ws = new WebSocket(url, ['foxglove.websocket.v1']);
    ws.binaryType = 'arraybuffer';
    ws.onopen = () => { $('conn').textContent = 'connected'; $('conn').className = 'ok'; };
    ws.onmessage = (ev) => (typeof ev.data === 'string' ? onText(ev.data) : onBinary(ev.data));
    ws.onclose = () => {
      $('conn').textContent = 'disconnected, retrying'; $('conn').className = 'bad';
      setTimeout(connect, 2000);
    };
  }

  $('pb-toggle').onclick = () => {
    const pause = view.playbackState === 'playing' || view.playbackState === 'restarted';
    playbackRequest(!pause, null);
  };
  $('pb-restart').onclick = () => playbackRequest(true, view.dataStart);

  // ---- Header -----------------------------------------------------------------------------------
  function updateHeader() {
    if (!headerDirty) return;
    headerDirty = false;
    const others = [...view.vehicles].filter((v) => v !== view.sc);
    $('sc').textContent = (view.sc || '–') + (others.length ? ' (also ' + others.join(', ') + ': ?sc=ID)' : '');
    const st = view.state;
    if (st) {
      $('tick').textContent = String(st.header.tick);
      $('simtime').textContent = (st.header.sim_time_ns / 1e9).toFixed(3);
    }
    const rs = $('run-state');
    if (view.status) { rs.textContent = view.status.run_state; rs.className = view.status.run_state; }
    const ec = $('eclipse');
    const env = view.env;
    if (!env) { ec.textContent = 'no environment message'; ec.className = ''; }
    else if (env.flags & 16) {
      ec.textContent = (ECLIPSE[env.eclipse] || env.eclipse) + ' (ν ' + env.shadow_factor.toFixed(3) + ')';
      ec.className = ECLIPSE[env.eclipse] || '';
    } else { ec.textContent = 'no shadow model'; ec.className = ''; }
    const active = [...view.faults.values()].filter((f) => f.active)
      .sort((a, b) => a.fault_index - b.fault_index)
      .map((f) => '#' + f.fault_index + ' ' + f.target + ' ' + (FAULT_MODES[f.mode] || 'mode ' + f.mode));
    const count = view.status ? view.status.faults_active : active.length;
    const fe = $('faults');
    if (count > active.length) active.push((count - active.length) + ' more active (StatusMsg)');
    fe.textContent = active.length ? active.join('; ') : 'none';
    fe.className = active.length ? 'active' : '';
    // The flight code: each stream's mode and last event, named by its declaration.
    const fsw = [...view.fsw.entries()].sort().map(([stream, f]) => {
      const d = view.fswStreams.get(stream);
      const mode = f.mode === null ? '–' : (d && d.modes[f.mode]) || '#' + f.mode;
      let text = stream + ': ' + mode;
      if (f.event !== null) {
        const e = d && d.events[f.event];
        text += ' · ' + (e ? e.name + ' (' + e.severity + ')' : '#' + f.event) + ' at ' + f.eventT.toFixed(3) + ' s';
      }
      return text;
    });
    $('fsw').textContent = fsw.length ? fsw.join('; ') : 'none';
    if (view.playback) {
      $('pb-state').textContent = view.playbackState || '–';
      $('pb-toggle').textContent = (view.playbackState === 'paused' || view.playbackState === 'ended') ? 'play' : 'pause';
    }
  }

  // ---- 3D view: boxes in B, projected on a 2D canvas ------------------------------------------
  const cam = { yaw: -0.9, pitch: 0.45, zoom: 1 };
  const mat = {
    quat(q) { // {x,y,z,w} → rotation matrix (rows)
      const { x, y, z, w } = q;
      return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]];
    },
    mul(a, b) { return a.map((r) => [0, 1, 2].map((j) => r[0] * b[0][j] + r[1] * b[1][j] + r[2] * b[2][j])); },
    apply(m, v) { return [0, 1, 2].map((i) => m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2]); },
    roty(a) { const c = Math.cos(a), s = Math.sin(a); return [[c, 0, s], [0, 1, 0], [-s, 0, c]]; },
    id: [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
  };
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];

  // The pose in B of frame `frame` (a rotation R and an origin o: p_B = R p + o), through /tf.
  function poseInB(frame) {
    let R = mat.id, o = [0, 0, 0];
    for (let guard = 0; frame !== view.sc + '/B'; guard++) {
      const tr = view.tf.get(frame);
      if (!tr || guard > 16) return null;
      const Rp = mat.quat(tr.rotation);
      const t = [tr.translation.x, tr.translation.y, tr.translation.z];
      o = add(mat.apply(Rp, o), t);
      R = mat.mul(Rp, R);
      frame = tr.parent_frame_id;
    }
    return { R, o };
  }

  const cssColor = (c) => [c.r * 255, c.g * 255, c.b * 255];

  // Boxes {c: centre in B, R: axes in B, h: half sizes, rgb} of the served configuration, or
  // of the default layout when the stream carries none.
  function boxes() {
    const out = [];
    if (view.scene && view.sc) {
      let complete = true;
      for (const e of view.scene.entities || []) {
        if (!e.frame_id.startsWith(view.sc + '/')) continue;
        const pose = e.frame_id === view.sc + '/B' ? { R: mat.id, o: [0, 0, 0] } : poseInB(e.frame_id);
        if (!pose) { complete = false; break; }
        for (const cube of e.cubes || []) {
          const p = cube.pose.position, s = cube.size;
          out.push({
            c: add(mat.apply(pose.R, [p.x, p.y, p.z]), pose.o),
            R: mat.mul(pose.R, mat.quat(cube.pose.orientation)),
            h: [s.x / 2, s.y / 2, s.z / 2], rgb: cssColor(cube.color), a: cube.color.a,
          });
        }
      }
      if (complete && out.length) return out;
      out.length = 0;
    }
    // Default layout: a 1 m hub; pair k on the +x (k even) or −x (k odd) face, hinged about
    // B's y axis, panel 1 turned by θ1, panel 2 by θ1 + θ2, each 1.5 m × 1 m.
    out.push({ c: [0, 0, 0], R: mat.id, h: [0.5, 0.5, 0.5], rgb: [190, 190, 200] });
    let k = 0;
    for (const e of (view.state && view.state.effectors) || []) {
      if (e.kind !== 1) continue;
      const side = k % 2 === 0 ? 1 : -1;
      const z = 0.3 * Math.floor(k / 2) * (Math.floor(k / 2) % 2 ? -1 : 1);
      const R1 = mat.roty(-side * e.states[0]);
      const R2 = mat.mul(R1, mat.roty(-side * e.states[2]));
      const hinge1 = [side * 0.5, 0, z];
      const hinge2 = add(hinge1, mat.apply(R1, [side * 1.5, 0, 0]));
      out.push({ c: add(hinge1, mat.apply(R1, [side * 0.75, 0, 0])), R: R1, h: [0.75, 0.5, 0.02], rgb: [40, 80, 205] });
      out.push({ c: add(hinge2, mat.apply(R2, [side * 0.75, 0, 0])), R: R2, h: [0.75, 0.5, 0.02], rgb: [40, 80, 205] });
      k++;
    }
    return out;
  }

  // Spheres {c: centre in B, r: radius, rgb, a} of the served configuration (/scene: the tanks)
  // and of the latest state (/actuators: the propellant in them).
  function spheres() {
    const out = [];
    for (const update of [view.scene, view.actuators]) {
      for (const e of (update && view.sc && update.entities) || []) {
        if (!e.frame_id.startsWith(view.sc + '/')) continue;
        const pose = e.frame_id === view.sc + '/B' ? { R: mat.id, o: [0, 0, 0] } : poseInB(e.frame_id);
        if (!pose) continue;
        for (const s of e.spheres || []) {
          const p = s.pose.position;
          out.push({ c: add(mat.apply(pose.R, [p.x, p.y, p.z]), pose.o), r: s.size.x / 2, rgb: cssColor(s.color), a: s.color.a });
        }
      }
    }
    return out;
  }

  function fitCanvas(c) {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(c.clientWidth * dpr)), h = Math.max(1, Math.round(c.clientHeight * dpr));
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    return dpr;
  }

  function drawScene() {
    const canvas = $('scene');
    const dpr = fitCanvas(canvas);
    const g = canvas.getContext('2d');
    const W = canvas.width, H = canvas.height;
    g.fillStyle = '#0b0e13';
    g.fillRect(0, 0, W, H);
    const list = boxes();
    const balls = spheres();
    // What is drawn, in the page's text too (a headless browser's --dump-dom reads it).
    $('drawn').textContent = list.length + ' boxes, ' + balls.length + ' spheres';
    let extent = 1;
    for (const b of list) extent = Math.max(extent, Math.hypot(...b.c) + Math.hypot(...b.h));
    for (const s of balls) extent = Math.max(extent, Math.hypot(...s.c) + s.r);
    // Camera: yaw about B's z, then pitch; screen x right, z up, y into the screen.
    const cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw), cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch);
    const toCam = (p) => {
      const x1 = cy * p[0] - sy * p[1], y1 = sy * p[0] + cy * p[1];
      return [x1, cp * y1 - sp * p[2], sp * y1 + cp * p[2]];
    };
    const D = extent * 4;
    const scale = Math.min(W, H) * 0.4 / extent * cam.zoom;
    const proj = (p) => {
      const q = toCam(p);
      const k = D / (D + q[1]);
      return [W / 2 + q[0] * scale * k, H / 2 - q[2] * scale * k, q[1]];
    };
    const light = [-0.4, -0.6, 0.7]; // in camera coordinates: from the upper left, in front
    const faces = [];
    for (const b of list) {
      for (let ax = 0; ax < 3; ax++) {
        for (const sgn of [-1, 1]) {
          const n = [b.R[0][ax] * sgn, b.R[1][ax] * sgn, b.R[2][ax] * sgn];
          const u = (ax + 1) % 3, v = (ax + 2) % 3;
          const corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([a, c]) => {
            const local = [0, 0, 0];
            local[ax] = sgn * b.h[ax]; local[u] = a * b.h[u]; local[v] = c * b.h[v];
            return add(b.c, mat.apply(b.R, local));
          });
          const nc = toCam(n);
          const pts = corners.map(proj);
          const depth = pts.reduce((s, p) => s + p[2], 0) / 4;
          // Back faces (normal away from the camera) are hidden by the box's front.
          const centre = toCam(corners.reduce((s, p) => add(s, p), [0, 0, 0]).map((x) => x / 4));
          const toEye = [-centre[0], -D - centre[1], -centre[2]];
          if (nc[0] * toEye[0] + nc[1] * toEye[1] + nc[2] * toEye[2] <= 0) continue;
          const lum = 0.3 + 0.7 * Math.max(0, nc[0] * light[0] + nc[1] * light[1] + nc[2] * light[2]);
          faces.push({ pts, depth, rgb: b.rgb.map((x) => Math.round(x * lum)), a: b.a === undefined ? 1 : b.a });
        }
      }
    }
    // A sphere is a disc at its projected centre; its depth is its nearest point's, so a shell
    // is painted over the smaller sphere inside it.
    for (const s of balls) {
      const p = proj(s.c);
      const rpx = s.r * scale * D / (D + p[2]);
      faces.push({ disc: [p[0], p[1], rpx], depth: p[2] - s.r, rgb: s.rgb.map(Math.round), a: s.a });
    }
    faces.sort((a, b) => b.depth - a.depth);
    g.lineJoin = 'round';
    for (const f of faces) {
      if (f.disc) {
        g.beginPath();
        g.arc(f.disc[0], f.disc[1], f.disc[2], 0, 2 * Math.PI);
        g.fillStyle = 'rgba(' + f.rgb.join(',') + ',' + f.a + ')';
        g.fill();
        continue;
      }
      g.beginPath();
      f.pts.forEach((p, i) => (i ? g.lineTo(p[0], p[1]) : g.moveTo(p[0], p[1])));
      g.closePath();
      g.fillStyle = 'rgba(' + f.rgb.join(',') + ',' + f.a + ')';
      g.fill();
      g.strokeStyle = 'rgba(0,0,0,0.45)';
      g.lineWidth = dpr;
      g.stroke();
    }
    const arrow = (dir, len, color, label, width, dash) => {
      const n = Math.hypot(dir[0], dir[1], dir[2]);
      if (!(n > 0)) return;
      const tip = dir.map((x) => (x / n) * len);
      const a = proj([0, 0, 0]), b = proj(tip);
      g.strokeStyle = g.fillStyle = color;
      g.lineWidth = width * dpr;
      g.setLineDash(dash ? [4 * dpr, 4 * dpr] : []);
      g.beginPath(); g.moveTo(a[0], a[1]); g.lineTo(b[0], b[1]); g.stroke();
      g.setLineDash([]);
      const ang = Math.atan2(b[1] - a[1], b[0] - a[0]), hl = 9 * dpr;
      if (Math.hypot(b[0] - a[0], b[1] - a[1]) > hl) {
        g.beginPath(); g.moveTo(b[0], b[1]);
        g.lineTo(b[0] - hl * Math.cos(ang - 0.4), b[1] - hl * Math.sin(ang - 0.4));
        g.lineTo(b[0] - hl * Math.cos(ang + 0.4), b[1] - hl * Math.sin(ang + 0.4));
        g.closePath(); g.fill();
      }
      g.font = (11 * dpr) + 'px system-ui, sans-serif';
      g.fillText(label, b[0] + 4 * dpr, b[1] - 4 * dpr);
    };
    const L = extent * 0.85;
    // The inertial axes N seen from B (q_BN, scalar first), dashed.
    if (view.state && view.state.q_bn) {
      const q = view.state.q_bn;
      const R = mat.quat({ w: q[0], x: q[1], y: q[2], z: q[3] }); // rotates B vectors into N
      ['N1', 'N2', 'N3'].forEach((name, i) => arrow(R[i], L * 0.7, '#8a8a8a', name, 1, true));
    }
    arrow([1, 0, 0], L, '#ff5050', 'x_B', 2);
    arrow([0, 1, 0], L, '#50e070', 'y_B', 2);
    arrow([0, 0, 1], L, '#5090ff', 'z_B', 2);
    const env = view.env;
    if (env && (env.flags & 4)) {
      const nu = env.flags & 16 ? env.shadow_factor : 1;
      const c = [255, 210, 26].map((x) => Math.round(x * nu + 128 * (1 - nu)));
      arrow(env.sun_b, L * 1.25, 'rgb(' + c.join(',') + ')', nu < 1 ? 'Sun (ν ' + nu.toFixed(2) + ')' : 'Sun', 3);
    }
    if (env && (env.flags & 2)) {
      const b = env.b_b_t, mag = Math.hypot(b[0], b[1], b[2]) * 1e6;
      arrow(b, L * 1.1, '#1ad0e6', 'B ' + mag.toFixed(1) + ' µT', 3);
    }
    g.fillStyle = '#8b98a8';
    g.font = (11 * dpr) + 'px system-ui, sans-serif';
    const src = view.scene ? 'geometry of the served configuration' : 'default layout (no /scene in the stream)';
    g.fillText('body frame B of ' + (view.sc || '–') + ', ' + src, 8 * dpr, 16 * dpr);
  }

  // ---- Plots --------------------------------------------------------------------------------------
  function niceStep(span, n) {
    const raw = span / n, p = Math.pow(10, Math.floor(Math.log10(raw))), f = raw / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
  }
  const fmt = (x) => (x === 0 ? '0' : Math.abs(x) >= 1e4 || Math.abs(x) < 1e-3 ? x.toExponential(1) : String(+x.toPrecision(4)));

  function drawPlot(id, title, s, tEnd, empty) {
    const c = $(id);
    const dpr = fitCanvas(c);
    const g = c.getContext('2d');
    const W = c.width, H = c.height;
    g.fillStyle = '#0b0e13';
    g.fillRect(0, 0, W, H);
    g.font = (11 * dpr) + 'px system-ui, sans-serif';
    g.fillStyle = '#d8dee6';
    g.fillText(title, 8 * dpr, 14 * dpr);
    const n = s.length;
    if (!n || !s.labels.length) {
      g.fillStyle = '#8b98a8';
      g.fillText(n ? empty : 'waiting for data…', W / 2 - 60 * dpr, H / 2);
      return;
    }
    const left = 58 * dpr, right = W - 8 * dpr, top = 22 * dpr, bottom = H - 18 * dpr;
    // The last WINDOW_S seconds, or since the first sample while there are fewer.
    const t0 = Math.min(Math.max(tEnd - WINDOW_S, s.t[s.start]), tEnd - 1);
    const span = tEnd - t0;
    let lo = Infinity, hi = -Infinity;
    for (let i = s.start; i < s.t.length; i++) for (const v of s.v[i]) { if (v < lo) lo = v; if (v > hi) hi = v; }
    if (!(hi > lo)) { const m = Math.abs(hi) || 1; lo -= m * 0.1; hi += m * 0.1; }
    const pad = (hi - lo) * 0.08; lo -= pad; hi += pad;
    const X = (t) => left + (t - t0) / span * (right - left);
    const Y = (v) => bottom - (v - lo) / (hi - lo) * (bottom - top);
    g.strokeStyle = '#222a35'; g.lineWidth = dpr; g.fillStyle = '#8b98a8';
    const ys = niceStep(hi - lo, 4);
    for (let i = Math.ceil(lo / ys); i * ys <= hi; i++) {
      const v = i * ys;
      g.beginPath(); g.moveTo(left, Y(v)); g.lineTo(right, Y(v)); g.stroke();
      g.fillText(fmt(v), 4 * dpr, Y(v) + 4 * dpr);
    }
    const xs = niceStep(span, 6);
    for (let i = Math.ceil(t0 / xs); i * xs <= tEnd; i++) {
      const t = i * xs;
      if (t < 0) continue;
      g.beginPath(); g.moveTo(X(t), top); g.lineTo(X(t), bottom); g.stroke();
      g.fillText(fmt(t) + ' s', X(t) - 10 * dpr, H - 4 * dpr);
    }
    const stride = Math.max(1, Math.floor(n / (right - left)));
    g.save(); g.beginPath(); g.rect(left, top, right - left, bottom - top); g.clip();
    s.labels.forEach((label, k) => {
      g.strokeStyle = COLORS[k % COLORS.length];
      g.lineWidth = (k === 0 && s.labels[0] === '|σ|' ? 2.5 : 1.5) * dpr;
      g.beginPath();
      let first = true;
      for (let i = s.start; i < s.t.length; i += stride) {
        const x = X(s.t[i]), y = Y(s.v[i][k]);
        if (first) { g.moveTo(x, y); first = false; } else g.lineTo(x, y);
      }
      g.stroke();
    });
    g.restore();
    let lx = right;
    for (let k = s.labels.length - 1; k >= 0; k--) {
      const w = g.measureText(s.labels[k]).width + 22 * dpr;
      lx -= w;
      g.fillStyle = COLORS[k % COLORS.length];
      g.fillRect(lx, 9 * dpr, 12 * dpr, 3 * dpr);
      g.fillStyle = '#d8dee6';
      g.fillText(s.labels[k], lx + 15 * dpr, 14 * dpr);
    }
  }

  function drawPlots() {
    const tEnd = series.sigma.last();
    drawPlot('plot-sigma', 'attitude σ_BN (MRP) and |σ|', series.sigma, tEnd, '');
    drawPlot('plot-omega', 'body rates ω_BN [rad/s]', series.omega, tEnd, '');
    drawPlot('plot-wheels', 'reaction wheel speeds Ω [rad/s]', series.wheels, tEnd, 'no reaction wheels');
    drawPlot('plot-hinges', 'hinge angles θ1, θ2 [deg]', series.hinges, tEnd, 'no panels');
  }

  // ---- Mouse -------------------------------------------------------------------------------------
  const sceneCanvas = $('scene');
  let drag = null;
  sceneCanvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; sceneCanvas.setPointerCapture(e.pointerId); sceneCanvas.style.cursor = 'grabbing'; });
  sceneCanvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    cam.yaw -= (e.clientX - drag[0]) * 0.01;
    cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY];
    sceneDirty = true;
  });
  const endDrag = () => { drag = null; sceneCanvas.style.cursor = 'grab'; };
  sceneCanvas.addEventListener('pointerup', endDrag);
  sceneCanvas.addEventListener('pointercancel', endDrag);
  sceneCanvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    cam.zoom = Math.max(0.2, Math.min(8, cam.zoom * Math.exp(-e.deltaY * 0.001)));
    sceneDirty = true;
  }, { passive: false });
  sceneCanvas.addEventListener('dblclick', () => { cam.yaw = -0.9; cam.pitch = 0.45; cam.zoom = 1; sceneDirty = true; });
  window.addEventListener('resize', () => { sceneDirty = plotsDirty = true; });

  // ---- Loop ----------------------------------------------------------------------------------------
  function frame() {
    updateHeader();
    if (sceneDirty) { sceneDirty = false; drawScene(); }
    if (plotsDirty) { plotsDirty = false; drawPlots(); }
    requestAnimationFrame(frame);
  }
  setInterval(updateHeader, 100); // also while the tab is hidden (no animation frames)
  requestAnimationFrame(frame);
  connect();
})();
