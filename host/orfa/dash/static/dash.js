// The ORFA dashboard page: one card per board, built from the first
// snapshot of the server's event stream (/events) and updated in place by
// every later one. The controls POST JSON to /api/<addr>/<control>.
"use strict";

var built = {};          // addr -> "full" once the board's card exists

function $(id) { return document.getElementById(id); }

function el(tag, attrs, children) {
  var node = document.createElement(tag);
  Object.keys(attrs || {}).forEach(function (k) {
    if (k === "text") { node.textContent = attrs[k]; }
    else if (k === "cls") { node.className = attrs[k]; }
    else { node.setAttribute(k, attrs[k]); }
  });
  (children || []).forEach(function (c) { if (c) { node.appendChild(c); } });
  return node;
}

function setText(id, text) {
  var node = $(id);
  if (node && node.textContent !== String(text)) { node.textContent = text; }
}

function hex2(n) { return "0x" + ("0" + n.toString(16).toUpperCase()).slice(-2); }

// --- messages ---------------------------------------------------------------

function say(text, isError) {
  var box = $("message");
  box.textContent = text;
  box.className = "message " + (isError ? "error" : "ok");
  box.hidden = false;
}

// --- controls ---------------------------------------------------------------

function post(addr, kind, body) {
  return fetch("api/" + addr + "/" + kind, {
    method: "POST",
    headers: {"Content-Type": "application/json"},
    body: JSON.stringify(body)
  }).then(function (r) {
    return r.json().then(function (data) { return {ok: r.ok, status: r.status, data: data}; },
                         function () { return {ok: false, status: r.status, data: {error: r.statusText}}; });
  }).then(function (res) {
    if (res.ok) {
      say("0x" + addr + " " + kind + ": " + describeDone(res.data), false);
    } else {
      say("0x" + addr + " " + kind + ": " + (res.data.error || ("HTTP " + res.status)), true);
    }
  }, function (err) { say("0x" + addr + " " + kind + ": " + err, true); });
}

function describeDone(d) {
  if ("servo" in d) { return "channel " + d.servo + " set to " + d.us + " us"; }
  if ("motor" in d) { return "motor " + d.motor + " set to duty " + d.duty; }
  if ("adc" in d) {
    return (d.adc.length ? "channels " + d.adc.join(", ") + " on" : "every channel off") +
      " (" + d.reference + ", " + d.bits + " bits)";
  }
  var parts = ["P" + d.port + d.bit];
  if ("output" in d) { parts.push(d.output ? "output" : "input"); }
  if ("level" in d) { parts.push("level " + d.level); }
  return parts.join(" ");
}

// A number field's value: a number, or the text itself (the server says why
// it is wrong), never silently dropped.
function numberOf(input) {
  var v = input.value.trim();
  return v === "" || isNaN(Number(v)) ? v : Number(v);
}

function options(values, labels) {
  return values.map(function (v, i) {
    return el("option", {value: v, text: labels ? labels[i] : v});
  });
}

function range(n, from) {
  var out = [];
  for (var i = 0; i < n; i++) { out.push(i + (from || 0)); }
  return out;
}

// --- building a board's card --------------------------------------------------

function buildServo(b) {
  var id = "b-" + b.addr + "-servo";
  var grid = el("div", {cls: "servos"}, b.servo.map(function (s) {
    var pin = b.servo_pins && b.servo_pins[s.ch];
    return el("div", {cls: "servo", id: id + "-cell-" + s.ch}, [
      el("span", {cls: "ch", text: s.ch}),
      el("span", {cls: "pin dim", text: pin || ""}),
      el("span", {cls: "us", id: id + "-" + s.ch, text: "-"}),
      el("span", {cls: "deg dim", id: id + "-deg-" + s.ch, text: ""})
    ]);
  }));
  var ch = el("select", {id: id + "-ch"}, options(range(b.servo.length)));
  var us = el("input", {id: id + "-us", type: "text", inputmode: "numeric", value: "1500", size: "6"});
  var slider = el("input", {id: id + "-slider", type: "range",
                            min: b.limits.servo_min_us, max: b.limits.servo_max_us, step: "10", value: "1500"});
  var set = el("button", {id: id + "-set", type: "button", text: "Set"});
  var off = el("button", {id: id + "-off", type: "button", text: "Off"});
  slider.addEventListener("input", function () { us.value = slider.value; });
  slider.addEventListener("change", function () {
    post(b.addr, "servo", {channel: Number(ch.value), us: Number(slider.value)});
  });
  set.addEventListener("click", function () {
    post(b.addr, "servo", {channel: Number(ch.value), us: numberOf(us)});
  });
  off.addEventListener("click", function () {
    post(b.addr, "servo", {channel: Number(ch.value), us: 0});
  });
  return el("section", {cls: "part"}, [
    el("h3", {text: "Servos (width us, angle)"}), grid,
    el("div", {cls: "control"}, [el("label", {text: "channel"}), ch,
                                 el("label", {text: "us"}), us, slider, set, off])
  ]);
}

function buildMotor(b) {
  var id = "b-" + b.addr + "-motor";
  var rows = b.motor.map(function (m) {
    return el("div", {cls: "motor"}, [
      el("span", {cls: "ch", text: "motor " + m.n}),
      el("span", {cls: "bar"}, [el("span", {cls: "fill", id: id + "-bar-" + m.n})]),
      el("span", {cls: "us", id: id + "-" + m.n, text: "-"}),
      el("span", {cls: "dim", id: id + "-dir-" + m.n, text: ""})
    ]);
  });
  var n = el("select", {id: id + "-n"}, options(range(b.motor.length, 1)));
  var duty = el("input", {id: id + "-duty", type: "text", inputmode: "numeric", value: "0", size: "5"});
  var set = el("button", {id: id + "-set", type: "button", text: "Set"});
  var stop = el("button", {id: id + "-stop", type: "button", text: "Stop"});
  set.addEventListener("click", function () {
    post(b.addr, "motor", {motor: Number(n.value), duty: numberOf(duty)});
  });
  stop.addEventListener("click", function () {
    post(b.addr, "motor", {motor: Number(n.value), duty: 0});
  });
  return el("section", {cls: "part"}, [
    el("h3", {text: "Motors (duty -255..255)"})].concat(rows).concat([
    el("div", {cls: "control"}, [el("label", {text: "motor"}), n,
                                 el("label", {text: "duty"}), duty, set, stop])]));
}

function buildAdc(b) {
  var id = "b-" + b.addr + "-adc";
  var cells = range(b.adc.volts.length).map(function (ch) {
    return el("div", {cls: "adc"}, [
      el("span", {cls: "ch", text: "P" + b.adc_port + ch}),
      el("span", {cls: "us", id: id + "-" + ch, text: "-"})
    ]);
  });
  // the configuration: which channels convert, the reference, the resolution
  var boxes = range(b.adc.volts.length).map(function (ch) {
    var box = el("input", {id: id + "-on-" + ch, type: "checkbox", value: ch});
    box.checked = b.adc.enabled.indexOf(ch) >= 0;
    return el("label", {cls: "check"}, [box, document.createTextNode(String(ch))]);
  });
  var ref = el("select", {id: id + "-ref"}, options(["avcc", "internal", "aref"],
                                                     ["AVCC (5 V)", "internal (2.56 V)", "AREF pin"]));
  ref.value = b.adc.reference;
  var bits = el("select", {id: id + "-bits"}, options(["10", "8"], ["10 bits", "8 bits"]));
  bits.value = String(b.adc.bits);
  var set = el("button", {id: id + "-set", type: "button", text: "Set"});
  set.addEventListener("click", function () {
    var on = boxes.map(function (l) { return l.firstChild; })
      .filter(function (box) { return box.checked; })
      .map(function (box) { return Number(box.value); });
    post(b.addr, "adc", {channels: on, reference: ref.value, bits: Number(bits.value)});
  });
  return el("section", {cls: "part"}, [
    el("h3", {}, [document.createTextNode("ADC "),
                  el("span", {cls: "dim", id: id + "-config", text: ""})]),
    el("div", {cls: "adcs"}, cells),
    el("div", {cls: "control"}, [el("label", {text: "channels"})].concat(boxes).concat(
      [ref, bits, set]))
  ]);
}

function buildGpio(b) {
  var id = "b-" + b.addr + "-gpio";
  var head = el("tr", {}, [el("th", {text: "port"})].concat(range(8).reverse().map(function (bit) {
    return el("th", {text: bit});
  })));
  var rows = b.gpio.map(function (g) {
    return el("tr", {}, [el("th", {text: g.port})].concat(range(8).reverse().map(function (bit) {
      var label = "P" + g.port + bit;
      var fn = (b.pin_functions || {})[label];
      return el("td", {id: id + "-" + g.port + bit, title: label + (fn ? ": " + fn.join(", ") : ""),
                       cls: fn ? "line fixed" : "line"}, [
        el("span", {cls: "lv"}), el("span", {cls: "dir"})]);
    })));
  });
  var port = el("select", {id: id + "-port"}, options(b.gpio.map(function (g) { return g.port; })));
  var bit = el("select", {id: id + "-bit"}, options(range(8)));
  var level = el("select", {id: id + "-level"}, options(["", "1", "0"], ["level as is", "high (1)", "low (0)"]));
  var dir = el("select", {id: id + "-dir"}, options(["", "out", "in"], ["direction as is", "output", "input"]));
  var set = el("button", {id: id + "-set", type: "button", text: "Set"});
  set.addEventListener("click", function () {
    var body = {port: port.value, bit: Number(bit.value)};
    if (level.value !== "") { body.level = Number(level.value); }
    if (dir.value !== "") { body.output = dir.value === "out"; }
    post(b.addr, "gpio", body);
  });
  return el("section", {cls: "part"}, [
    el("h3", {text: "GPIO (level; o = output, i = input)"}),
    el("table", {cls: "gpio"}, [head].concat(rows)),
    el("div", {cls: "control"}, [el("label", {text: "line P"}), port, bit, level, dir, set])
  ]);
}

function buildBoard(b) {
  var id = "b-" + b.addr;
  var title = el("h2", {}, [
    document.createTextNode("0x" + b.addr + " "),
    el("span", {cls: "role " + b.role, text: b.role}),
    document.createTextNode(" " + b.name + " (" + b.board + ")")
  ]);
  var status = el("div", {cls: "status"}, [
    el("span", {}, [document.createTextNode("status "), el("b", {id: id + "-status", text: "-"})]),
    el("span", {}, [document.createTextNode("reset cause "), el("b", {id: id + "-reset", text: "-"})]),
    el("span", {}, [document.createTextNode("failsafe "), el("b", {id: id + "-failsafe", text: "-"})])
  ]);
  var parts = [title, status, el("div", {cls: "error", id: id + "-error", hidden: ""})];
  if (b.servo) { parts.push(buildServo(b)); }
  if (b.motor) { parts.push(buildMotor(b)); }
  if (b.adc) { parts.push(buildAdc(b)); }
  if (b.gpio) { parts.push(buildGpio(b)); }
  return el("article", {cls: "board", id: id}, parts);
}

// --- updating in place ----------------------------------------------------------

function update(b) {
  var id = "b-" + b.addr;
  var err = $(id + "-error");
  if (b.error) { err.textContent = b.error; err.hidden = false; return; }
  if (!b.status) { return; }
  err.hidden = true;
  setText(id + "-status", hex2(b.status.code).slice(2) + " " + b.status.name);
  $(id + "-status").title = b.status.text;
  setText(id + "-reset", b.reset_cause.length ? b.reset_cause.join(", ") : "none since cleared");
  setText(id + "-failsafe", b.failsafe_ms ? b.failsafe_ms + " ms" : "off");
  (b.servo || []).forEach(function (s) {
    setText(id + "-servo-" + s.ch, s.us ? s.us : "off");
    setText(id + "-servo-deg-" + s.ch, s.deg === null ? "" : (s.deg > 0 ? "+" : "") + s.deg.toFixed(1) + "\u00b0");
    $(id + "-servo-cell-" + s.ch).className = "servo" + (s.us ? " on" : "");
  });
  (b.motor || []).forEach(function (m) {
    setText(id + "-motor-" + m.n, m.duty);
    setText(id + "-motor-dir-" + m.n, m.direction);
    var fill = $(id + "-motor-bar-" + m.n);
    var pct = Math.abs(m.duty) / 255 * 50;
    fill.style.width = pct + "%";
    fill.style.left = (m.duty < 0 ? 50 - pct : 50) + "%";
    fill.className = "fill " + m.direction;
  });
  if (b.adc) {
    setText(id + "-adc-config", b.adc.reference + ", " + b.adc.bits + " bits" +
            (b.adc.enabled.length ? "" : ", no channel on"));
    b.adc.volts.forEach(function (v, ch) {
      setText(id + "-adc-" + ch, b.adc.enabled.indexOf(ch) < 0 ? "off" : v === null ? "on" : v.toFixed(3) + " V");
    });
  }
  (b.gpio || []).forEach(function (g) {
    for (var bit = 0; bit < 8; bit++) {
      var cell = $(id + "-gpio-" + g.port + bit);
      var level = (g.levels >> bit) & 1, out = (g.modes >> bit) & 1;
      cell.setAttribute("data-level", level);
      cell.setAttribute("data-output", out);
      cell.firstChild.textContent = level;
      cell.lastChild.textContent = out ? "o" : "i";
      cell.className = cell.className.replace(/ (hi|lo)/g, "") + (level ? " hi" : " lo");
    }
  });
}

function show(snap) {
  setText("seq", snap.seq);
  setText("stamp", new Date(snap.time * 1000).toLocaleTimeString());
  setText("port", snap.port);
  var boards = $("boards");
  snap.boards.forEach(function (b) {
    // a board that failed its first read gets a card of its error, and its
    // whole card once values come
    if (!built[b.addr] || (built[b.addr] === "partial" && !b.error)) {
      var card = buildBoard(b), old = $("b-" + b.addr);
      if (old) { boards.replaceChild(card, old); } else { boards.appendChild(card); }
      built[b.addr] = b.error ? "partial" : "full";
    }
    update(b);
  });
  var others = $("others");
  others.hidden = snap.others.length === 0;
  others.textContent = "Other devices on the bus (8-bit): " +
    snap.others.map(function (a) { return "0x" + a; }).join(" ");
}

// --- the stream -------------------------------------------------------------------

function connect() {
  var source = new EventSource("events");
  source.addEventListener("snapshot", function (ev) { show(JSON.parse(ev.data)); });
  source.onopen = function () { $("link").textContent = "live"; $("link").className = "link up"; };
  source.onerror = function () { $("link").textContent = "reconnecting"; $("link").className = "link down"; };
}

connect();
