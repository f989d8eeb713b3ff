// railcrash run report: header, animation of the planar model, event log, plots (uPlot, inlined
// from npm by the build), force-deformation loops and the energy partition. The data come
// from the JSON blocks of the page (written by src/report/report.cpp). Every text from the
// run (names, messages, events) is put in with textContent, never parsed as HTML.
"use strict";
(function () {
  function parseBlock(id, problems) {
    var text = document.getElementById(id).textContent;
    try {
      return JSON.parse(text);
    } catch (e) {
      problems.push(id.replace("-json", ".json") + " cannot be read (" + e.message + "): the file is broken or was cut off");
      return null;
    }
  }
  function el(tag, attributes, text) {
    var node = document.createElement(tag);
    for (var k in attributes || {}) node.setAttribute(k, attributes[k]);
    if (text !== undefined && text !== null) node.textContent = String(text);
    return node;
  }
  function fmt(value, digits) {
    if (value === null || value === undefined || typeof value !== "number" || !isFinite(value)) return "-";
    return Number(value.toPrecision(digits || 4)).toString();
  }

  var problems = [];
  var data = parseBlock("report-data", problems) || {problems: [], plots: [], loops: [], events: [], frames: null};
  var summary = parseBlock("summary-json", problems);
  var model = parseBlock("model-json", problems);
  problems = (data.problems || []).concat(problems);
  var check = {errors: window.railcrashErrors, plots: [], frames: null};

  // ---------------------------------------------------------------- a study folder (converge, readings, sensitivity, sweep)
  function csvRows(text) {  // RFC 4180 fields
    var rows = [], row = [""], quoted = false;
    for (var i = 0; i < text.length; ++i) {
      var c = text[i];
      if (quoted) {
        if (c === '"' && text[i + 1] === '"') { row[row.length - 1] += '"'; ++i; }
        else if (c === '"') quoted = false;
        else row[row.length - 1] += c;
      } else if (c === '"') quoted = true;
      else if (c === ",") row.push("");
      else if (c === "\n") { rows.push(row); row = [""]; }
      else if (c !== "\r") row[row.length - 1] += c;
    }
    if (row.length > 1 || row[0] !== "") rows.push(row);
    return rows;
  }
  function table(rows) {
    var t = el("table", {"class": "facts"});
    rows.forEach(function (cells, k) {
      var tr = el("tr");
      cells.forEach(function (cell) { tr.appendChild(el(k === 0 ? "th" : "td", {}, cell)); });
      t.appendChild(tr);
    });
    return t;
  }
  // The charts of a study page (uPlot): a sweep's responses against each factor with the main
  // effect (the mean at each level) and the points coloured by discrete outcome (runs.csv's
  // branch, issue 40) with every branch change marked; a sensitivity study's tornado chart of
  // first-order effects per response; a convergence study's error against cost.
  var studyPalette = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
  var studyCharts = [];
  function isNumber(text) { return text !== undefined && text !== null && String(text).trim() !== "" && isFinite(Number(text)); }
  function studyChart(container, id, options, columns, note, extra) {
    var box = el("div", {"class": "plot study-chart"});
    container.appendChild(box);
    var u = new uPlot(options, columns, box);
    if (note) box.appendChild(el("div", {"class": "note"}, note));
    var points = 0;
    columns.slice(1).forEach(function (c) { c.forEach(function (v) { if (v !== null && v !== undefined) ++points; }); });
    var entry = {id: id, series: columns.length - 1, points: points, drawn: !!u.ctx};
    // The y axis' range as drawn (uPlot sets the scales at its first draw, after this).
    Object.defineProperty(entry, "y", {enumerable: true, get: function () { return u.scales.y ? [u.scales.y.min, u.scales.y.max] : null; }});
    for (var k in extra || {}) entry[k] = extra[k];
    studyCharts.push(entry);
    return entry;
  }
  function verticalMarks(marks, colour, text) {  // uPlot draw hook: dashed vertical lines at x values, labelled
    return function (u) {
      var c = u.ctx;
      marks.slice().sort(function (a, b) { return a - b; }).forEach(function (x, k) {
        var px = u.valToPos(x, "x", true);
        if (!isFinite(px)) return;
        c.save();
        c.strokeStyle = colour;
        c.lineWidth = 2 * (window.devicePixelRatio || 1);
        c.setLineDash([6, 4]);
        c.beginPath();
        c.moveTo(px, u.bbox.top);
        c.lineTo(px, u.bbox.top + u.bbox.height);
        c.stroke();
        c.fillStyle = colour;
        c.font = Math.round(11 * (window.devicePixelRatio || 1)) + "px sans-serif";
        c.fillText(text, px + 4, u.bbox.top + (14 + 14 * (k % 3)) * (window.devicePixelRatio || 1));  // staggered: close marks stay legible
        c.restore();
      });
    };
  }

  // An axis whose tick labels stay short: values of 1e5 and more (or below 1e-3) in units of a power of ten named in its label.
  function scaledAxis(label, values, extra) {
    var largest = 0;
    values.forEach(function (v) { if (isFinite(v) && Math.abs(v) > largest) largest = Math.abs(v); });
    var exponent = largest >= 1e5 || (largest > 0 && largest < 1e-3) ? Math.floor(Math.log10(largest)) : 0;
    var axis = {label: label + (exponent ? " [x 1e" + exponent + "]" : ""), values: tickLabels(Math.pow(10, -exponent))};
    for (var k in extra || {}) axis[k] = extra[k];
    return axis;
  }
  function logLabels(u, splits) {  // a log axis: 0.01 ... 1000 as numbers, else 1e-5
    return splits.map(function (v) {
      if (v === null || v === undefined || !(v > 0)) return "";
      return v >= 0.01 && v < 1e4 ? String(Number(v.toPrecision(3))) : v.toExponential(0).replace("e+", "e");
    });
  }

  // A response's axis: 5 % beyond its runs' range; one value in every run (R2 = 0 in a model
  // without an anticlimber) gets 0..1, or 10 % either side of it, not uPlot's default 0..100.
  function responseRange(u, min, max) {
    if (min === null || max === null || !isFinite(min) || !isFinite(max)) return [0, 1];
    if (max === min) return min === 0 ? [0, 1] : [min - 0.1 * Math.abs(min), max + 0.1 * Math.abs(max)];
    var pad = 0.05 * (max - min);
    return [min - pad, max + pad];
  }

  function sweepCharts(box, rows) {
    var header = rows[0] || [], body = rows.slice(1).filter(function (r) { return r.length === header.length; });
    var iHash = header.indexOf("hash"), iStatus = header.indexOf("status"), iWall = header.indexOf("wall_seconds");
    var iBranch = header.indexOf("branch"), iRun = header.indexOf("run");
    if (iHash < 0 || iStatus < 0) return {};
    var notResponses = {integrator_used: true, euler_from_t: true, wall_seconds: true, message: true, outcomes: true, branch: true};
    var factors = [], responses = [];
    for (var f = iHash + 1; f < iStatus; ++f) factors.push(f);
    for (var r = iStatus + 1; r < (iWall > iStatus ? iWall : header.length); ++r)
      if (!notResponses[header[r]]) responses.push(r);
    var ok = body.filter(function (row) { return row[iStatus] === "ok"; });
    responses = responses.filter(function (r) { return ok.some(function (row) { return isNumber(row[r]); }); });
    // Branches: run 0's first, then in order of appearance.
    var branches = [], branchOf = function (row) { return iBranch >= 0 ? row[iBranch] : ""; };
    var base = ok.filter(function (row) { return row[iRun] === "0"; })[0];
    if (base) branches.push(branchOf(base));
    ok.forEach(function (row) { if (branches.indexOf(branchOf(row)) < 0) branches.push(branchOf(row)); });
    var colourOf = function (b) { return studyPalette[branches.indexOf(b) % studyPalette.length]; };
    box.appendChild(el("h2", {}, "Responses against each factor"));
    var intro = "Each chart: one response against one factor; a point per ok run, coloured by its discrete outcome (runs.csv, column branch); " +
                "the black line is the main effect (the response's mean over the runs at each level of the factor).";
    if (branches.length > 1) intro += " A red dashed line marks a branch change: two runs that differ only in this factor end on different branches " +
                                      "between these levels, and a response may jump there (a finite difference across it is not a sensitivity).";
    box.appendChild(el("p", {}, intro));
    if (iBranch >= 0) {
      var legend = el("div", {"class": "branch-legend"});
      branches.forEach(function (b, k) {
        var count = ok.filter(function (row) { return branchOf(row) === b; }).length;
        var line = el("div");
        var swatch = el("span", {"class": "swatch-dot"});
        swatch.style.background = colourOf(b);
        line.appendChild(swatch);
        line.appendChild(el("span", {}, "branch " + (k + 1) + (k === 0 && base ? " (run 0's)" : "") + ", " + count + " run" + (count === 1 ? "" : "s") + ": "));
        line.appendChild(el("code", {}, b || "(none)"));
        legend.appendChild(line);
      });
      box.appendChild(legend);
    }
    var chartsBox = el("div");
    box.appendChild(chartsBox);
    var changes = 0, charts = 0;
    factors.forEach(function (fi) {
      var numeric = ok.every(function (row) { return isNumber(row[fi]); });
      var levels = [];
      ok.forEach(function (row) { if (levels.indexOf(row[fi]) < 0) levels.push(row[fi]); });
      if (numeric) levels.sort(function (a, b) { return Number(a) - Number(b); });
      var xOf = function (row) { return numeric ? Number(row[fi]) : levels.indexOf(row[fi]); };
      // Branch changes along this factor: runs equal in every other factor, adjacent in this one, on different branches.
      var groups = {};
      ok.forEach(function (row) {
        var key = factors.filter(function (g) { return g !== fi; }).map(function (g) { return row[g]; }).join("\u0001");
        (groups[key] = groups[key] || []).push(row);
      });
      var marks = [];
      Object.keys(groups).forEach(function (key) {
        var g = groups[key].slice().sort(function (a, b) { return xOf(a) - xOf(b); });
        for (var k = 1; k < g.length; ++k)
          if (branchOf(g[k]) !== branchOf(g[k - 1]) && xOf(g[k]) !== xOf(g[k - 1])) {
            var mid = (xOf(g[k]) + xOf(g[k - 1])) / 2;
            if (marks.indexOf(mid) < 0) marks.push(mid);
          }
      });
      changes += marks.length;
      responses.forEach(function (ri) {
        if (charts >= 40) return;
        var runs = ok.filter(function (row) { return isNumber(row[ri]); }).sort(function (a, b) { return xOf(a) - xOf(b); });
        if (!runs.length) return;
        ++charts;
        var xs = runs.map(xOf);
        var columns = [xs];
        var mean = xs.map(function () { return null; });
        levels.forEach(function (level) {
          var at = runs.filter(function (row) { return row[fi] === level; });
          if (!at.length) return;
          var sum = 0;
          at.forEach(function (row) { sum += Number(row[ri]); });
          mean[runs.indexOf(at[0])] = sum / at.length;
        });
        columns.push(mean);
        var series = [{label: header[fi]}, {label: "main effect (mean)", stroke: "#222", width: 1.5, spanGaps: true, points: {show: false}}];
        branches.forEach(function (b, k) {
          columns.push(runs.map(function (row) { return branchOf(row) === b ? Number(row[ri]) : null; }));
          series.push({label: "branch " + (k + 1), stroke: colourOf(b), fill: colourOf(b), paths: function () { return null; },
                       points: {show: true, size: 9, space: 0, fill: colourOf(b), stroke: colourOf(b)}});
        });
        var xAxis = scaledAxis(header[fi], xs);
        var xScale = {time: false};
        if (!numeric) {
          xAxis.values = function (u, splits) { return splits.map(function (v) { return levels[v] !== undefined && v === Math.round(v) ? levels[v] : ""; }); };
          xAxis.splits = function () { return levels.map(function (l, k) { return k; }); };
          xScale.range = [-0.5, levels.length - 0.5];
        } else {
          // Padded beyond the first and last level: uPlot finds the points in view by searching x, and with
          // several runs at the last level (equal x) it would stop at the first of them.
          var low = xs[0], high = xs[xs.length - 1], pad = high > low ? 0.06 * (high - low) : Math.abs(low || 1) * 0.1;
          xScale.range = [low - pad, high + pad];
        }
        studyChart(chartsBox, "sweep:" + header[ri] + ":" + header[fi], {
          title: header[ri] + " against " + header[fi], width: 480, height: 300,
          scales: {x: xScale, y: {range: responseRange}},
          axes: [xAxis, scaledAxis(header[ri], runs.map(function (row) { return Number(row[ri]); }), {size: 70})],
          series: series, legend: {live: false}, cursor: {drag: {x: false, y: false}},
          hooks: {draw: [verticalMarks(marks, "#c00", "branch change")]}
        }, columns, marks.length ? marks.length + " branch change" + (marks.length === 1 ? "" : "s") + " along " + header[fi] : "",
           {marks: marks.slice().sort(function (a, b) { return a - b; })});
      });
    });
    return {branches: branches.length, changes: changes};
  }

  function tornadoCharts(box, files) {
    var first = files["sensitivity_first_order.csv"];
    if (!first) return {};
    var rows = csvRows(first.text), header = rows[0] || [];
    var terms = rows.slice(1).filter(function (r) { return r.length === header.length && r[0] !== "1"; });
    var branchRows = files["sensitivity_branches.csv"] ? csvRows(files["sensitivity_branches.csv"].text) : [];
    var bHeader = branchRows[0] || [], branchByParameter = {};
    branchRows.slice(1).forEach(function (r) { if (r.length === bHeader.length) branchByParameter[r[bHeader.indexOf("parameter")]] = r; });
    box.appendChild(el("h2", {}, "Tornado charts: first-order effects"));
    box.appendChild(el("p", {}, "Each response's first-order coefficients (sensitivity_first_order.csv: the change of the response for a unit change " +
      "of the parameter's scale factor), largest magnitude on top." + (Object.keys(branchByParameter).length ?
      " A parameter marked * crosses a branch change (sensitivity_branches.csv): its grey bar is the effect within run 0's branch." : "")));
    var chartsBox = el("div");
    box.appendChild(chartsBox);
    var responses = 0;
    header.forEach(function (response, c) {  // (a function per response: the axis callbacks keep their own names)
      if (c < 2) return;
      var list = terms.filter(function (r) { return isNumber(r[c]); }).map(function (r) {
        var b = branchByParameter[r[0]], within = b ? b[bHeader.indexOf("within_" + header[c])] : undefined;
        return {name: r[0] + (b ? " *" : ""), value: Number(r[c]), within: isNumber(within) ? Number(within) : null};
      });
      list.sort(function (a, b) { return Math.abs(b.value) - Math.abs(a.value); });
      list = list.slice(0, 25);
      if (!list.length) return;
      ++responses;
      var names = list.map(function (e) { return e.name; });
      var index = list.map(function (e, k) { return k; });
      var positive = list.map(function (e) { return e.value >= 0 ? e.value : null; });
      var negative = list.map(function (e) { return e.value < 0 ? e.value : null; });
      var within = list.map(function (e) { return e.within; });
      var series = [{label: "parameter"},
        {label: "increases " + header[c], fill: "#d62728", stroke: "#d62728", paths: uPlot.paths.bars({size: [0.7, 60]}), points: {show: false}},
        {label: "decreases " + header[c], fill: "#1f77b4", stroke: "#1f77b4", paths: uPlot.paths.bars({size: [0.7, 60]}), points: {show: false}}];
      var columns = [index, positive, negative];
      if (within.some(function (v) { return v !== null; })) {
        series.push({label: "within run 0's branch", fill: "rgba(90,90,90,0.75)", stroke: "#333", paths: uPlot.paths.bars({size: [0.3, 30]}), points: {show: false}});
        columns.push(within);
      }
      studyChart(chartsBox, "tornado:" + header[c], {
        title: header[c] + ": first-order effects", width: 520, height: 60 + 24 * list.length,
        scales: {x: {time: false, ori: 1, dir: -1, range: [-0.5, list.length - 0.5]}, y: {ori: 0, dir: 1}},
        axes: [{side: 3, size: 110, gap: 4, splits: function () { return index; },
                values: function (u, splits) { return splits.map(function (v) { return names[v] || ""; }); }, grid: {show: false}},
               {side: 2, label: "first-order coefficient", values: tickLabels(1)}],
        series: series, legend: {live: false}, cursor: {show: false}
      }, columns, "", {order: names});
    });
    return {responses: responses, flagged: Object.keys(branchByParameter).length};
  }

  function convergeCharts(box, rows) {
    var header = rows[0] || [], body = rows.slice(1).filter(function (r) { return r.length === header.length && r[header.indexOf("status")] === "ok"; });
    var iMethod = header.indexOf("method"), iCost = header.indexOf("residual_evaluations"), iWall = header.indexOf("wall_s");
    if (iMethod < 0 || iCost < 0) return {};
    var quantities = header.filter(function (h) { return /_error$/.test(h); }).filter(function (h) {
      var i = header.indexOf(h);
      return body.some(function (r) { return r[iMethod] !== "reference" && isNumber(r[i]) && Number(r[i]) > 0; });
    });
    box.appendChild(el("h2", {}, "Error against cost"));
    box.appendChild(el("p", {}, "Each quantity's relative error against the reference run, over the residual evaluations each run took (log-log): " +
      "one line per method (Euler at its steps, IDA at its tolerances); further down and to the left is better."));
    var chartsBox = el("div");
    box.appendChild(chartsBox);
    var methods = [];
    body.forEach(function (r) { if (r[iMethod] !== "reference" && methods.indexOf(r[iMethod]) < 0) methods.push(r[iMethod]); });
    quantities.forEach(function (q) {
      var iq = header.indexOf(q);
      var runs = body.filter(function (r) { return r[iMethod] !== "reference" && isNumber(r[iq]) && Number(r[iq]) > 0 && Number(r[iCost]) > 0; });
      runs.sort(function (a, b) { return Number(a[iCost]) - Number(b[iCost]); });
      if (!runs.length) return;
      var columns = [runs.map(function (r) { return Number(r[iCost]); })];
      var series = [{label: "residual evaluations"}];
      methods.forEach(function (m, k) {
        columns.push(runs.map(function (r) { return r[iMethod] === m ? Number(r[iq]) : null; }));
        series.push({label: m, stroke: studyPalette[k % studyPalette.length], width: 2, spanGaps: true,
                     points: {show: true, size: 7, space: 0, fill: studyPalette[k % studyPalette.length]}});
      });
      studyChart(chartsBox, "converge:" + q, {
        title: q.replace(/_error$/, "") + ": relative error against cost", width: 520, height: 320,
        scales: {x: {time: false, distr: 3}, y: {distr: 3}},
        axes: [{label: "residual evaluations", values: logLabels}, {label: "relative error", size: 70, values: logLabels}],
        series: series, legend: {live: false}
      }, columns);
    });
    return {quantities: quantities.length};
  }

  // Markdown: headings as headings, tables as tables, the rest as paragraphs with `code` spans (text, never markup).
  function markdown(box, text) {
    var lines = text.split("\n"), pending = [], tables = 0;
    function flush() { if (pending.length) { box.appendChild(table(pending)); ++tables; pending = []; } }
    function paragraph(tag, line) {
      var node = el(tag);
      line.split("`").forEach(function (part, k) {
        if (k % 2) node.appendChild(el("code", {}, part));
        else node.appendChild(document.createTextNode(part.replace(/\*\*/g, "")));
      });
      return node;
    }
    lines.forEach(function (line) {
      var trimmed = line.trim();
      if (trimmed.charAt(0) === "|") {
        if (/^\|[\s|:-]+\|$/.test(trimmed)) return;  // the separator row
        pending.push(trimmed.replace(/^\||\|$/g, "").split("|").map(function (c) { return c.trim(); }));
        return;
      }
      flush();
      var heading = /^(#{1,6})\s+(.*)$/.exec(trimmed);
      if (heading) box.appendChild(paragraph("h" + Math.min(6, heading[1].length + 2), heading[2]));  // under the page's h1 and the file's h2
      else if (trimmed) box.appendChild(paragraph("p", trimmed));
    });
    flush();
    return tables;
  }

  function studyReport() {
    ["animation-section", "plots-section", "loops-section", "zones-section", "energy-section"].forEach(function (id) {
      document.getElementById(id).hidden = true;
    });
    var head = document.getElementById("header");
    head.textContent = "";
    head.appendChild(el("h1", {}, "railcrash " + ({converge: "convergence", readings: "reading", sensitivity: "sensitivity", sweep: "sweep"}[data.study] || data.study) +
                                  " study: " + data.run_dir));
    var box = el("section");
    document.body.insertBefore(box, document.getElementById("footer"));
    var files = {};
    data.files.forEach(function (file) { files[file.name] = file; });
    var found = {};
    if (typeof window.uPlot !== "function") {
      box.appendChild(el("p", {"class": "no-library"}, "This railcrash was built without its plotting library (npm was not available when it " +
        "was built): the study's charts are left out."));
    } else {
      try {
        if (data.study === "sweep" && files["runs.csv"]) found = sweepCharts(box, csvRows(files["runs.csv"].text));
        if (data.study === "sensitivity") found = tornadoCharts(box, files);
        if (data.study === "converge" && files["converge.csv"]) found = convergeCharts(box, csvRows(files["converge.csv"].text));
      } catch (e) {
        window.railcrashErrors.push("study charts: " + e.message);
      }
    }
    var tables = 0;
    if (data.chart) {
      box.appendChild(el("h2", {}, "Convergence chart (converge.svg)"));
      box.appendChild(el("img", {src: data.chart, alt: "converge.svg"}));
    }
    data.files.forEach(function (file) {
      box.appendChild(el("h2", {}, file.name));
      if (file.kind === "csv") {
        box.appendChild(table(csvRows(file.text)));
        ++tables;
        return;
      }
      tables += markdown(box, file.text);
    });
    document.getElementById("footer").textContent = "railcrash report of a " + data.study + " folder";
    var selfCheck = document.getElementById("self-check");
    var writeCheck = function () {
      selfCheck.textContent = JSON.stringify({errors: window.railcrashErrors, study: data.study, tables: tables, chart: !!data.chart,
                                              charts: studyCharts, found: found, headings: box.querySelectorAll("h3, h4, h5").length});
      selfCheck.setAttribute("data-status", window.railcrashErrors.length ? "errors" : "ran");
    };
    writeCheck();
    // Again once uPlot has drawn (it sets its scales at the first draw, in an animation frame):
    // the charts' y ranges as drawn.
    requestAnimationFrame(function () { setTimeout(writeCheck, 0); });
  }

  // ---------------------------------------------------------------- runs side by side (issue 39 item 5)
  // `railcrash report RUN_A RUN_B [...]`: each run's identity, the summary tables with the
  // differences to the first run (computed by report.cpp write_comparison), the outcome
  // signatures, and the time histories with a line per run.
  function compareReport() {
    ["animation-section", "plots-section", "loops-section", "zones-section", "energy-section"].forEach(function (id) {
      document.getElementById(id).hidden = true;
    });
    var runs = data.runs, n = runs.length;
    var colours = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
    var check = {errors: [], compare: true, runs: n, tables: [], charts: [], outcomes: ""};
    var problemBox = document.getElementById("problems");
    problems.forEach(function (p) {
      problemBox.appendChild(el("div", {"class": /FAILED|no summary/.test(p) ? "problem failed" : "problem"}, p));
    });
    var head = document.getElementById("header");
    head.textContent = "";
    head.appendChild(el("h1", {}, "railcrash: " + n + " runs side by side"));
    head.appendChild(el("p", {}, "Differences are each run's value minus the first run's (" + runs[0].label +
                                 "), and that difference in % of the first run's magnitude."));
    var box = el("section", {id: "compare"});
    document.body.insertBefore(box, document.getElementById("footer"));
    function number(v) {
      if (v === null || v === undefined) return "\u2013";
      if (v === 0) return "0";
      var a = Math.abs(v);
      return a >= 1e5 || a < 1e-3 ? v.toExponential(3) : String(Number(v.toPrecision(4)));
    }
    function signed(v) { return v === null || v === undefined ? "\u2013" : (v > 0 ? "+" : "") + number(v); }
    // Identity of each run.
    box.appendChild(el("h2", {}, "Runs"));
    var identity = el("table", {"class": "compare", id: "compare-runs"});
    var tr = el("tr");
    tr.appendChild(el("th", {}, ""));
    runs.forEach(function (r, k) {
      var th = el("th", {}, r.label);
      th.style.borderBottom = "3px solid " + colours[k % colours.length];
      tr.appendChild(th);
    });
    identity.appendChild(tr);
    function identityRow(name, cell) {
      var row = el("tr");
      row.appendChild(el("th", {}, name));
      runs.forEach(function (r, k) {
        var c = cell(r, k);
        row.appendChild(el("td", c.cls ? {"class": c.cls} : {}, c.text));
      });
      identity.appendChild(row);
    }
    identityRow("folder", function (r) { return {text: r.folder}; });
    identityRow("model", function (r) { return {text: r.model}; });
    identityRow("integrator", function (r) { return {text: r.integrator}; });
    identityRow("status", function (r) {
      return {text: r.status + (r.message ? ": " + r.message : ""), cls: r.status === "ok" ? "status-ok" : "status-failed"};
    });
    identityRow("t reached [s]", function (r) { return {text: number(r.t_reached)}; });
    identityRow("output rows (" + runs.map(function (r) { return r.file; }).filter(function (f, k, a) { return a.indexOf(f) === k; }).join(", ") + ")",
                function (r) { return {text: String(r.rows)}; });
    identityRow("settings (--set)", function (r) { return {text: r.settings.length ? r.settings.join(" ") : "none"}; });
    identityRow("run id", function (r) { return {text: r.run_id}; });
    var differing = 0;
    identityRow("outcome branch", function (r, k) {
      var same = data.outcomes[k].branch === data.outcomes[0].branch;
      if (!same) ++differing;
      return {text: (data.outcomes[k].branch || "(no discrete outcome)") + (k ? (same ? " (same as " + runs[0].label + ")" : " (DIFFERS)") : ""),
              cls: k && !same ? "differs" : ""};
    });
    identityRow("outcome signature", function (r, k) { return {text: data.outcomes[k].signature || "\u2013"}; });
    box.appendChild(identity);
    check.outcomes = differing ? "differ" : "same";

    // The summary tables.
    data.tables.forEach(function (t) {
      var container = box;
      if (t.id === "peaks") {
        var details = el("details", {"class": "compare-peaks"});
        details.appendChild(el("summary", {}, t.title + ": " + t.rows.length + " rows"));
        box.appendChild(details);
        container = details;
      } else {
        box.appendChild(el("h2", {}, t.title));
      }
      var table = el("table", {"class": "compare", id: "compare-" + t.id});
      var header = el("tr");
      header.appendChild(el("th", {}, "quantity"));
      runs.forEach(function (r, k) {
        header.appendChild(el("th", {}, r.label + (t.unit ? " [" + t.unit + "]" : "")));
        if (k) {
          header.appendChild(el("th", {}, "\u0394 " + r.label + (t.unit ? " [" + t.unit + "]" : "")));
          header.appendChild(el("th", {}, "\u0394 " + r.label + " [%]"));
        }
      });
      table.appendChild(header);
      var cells = 0;
      t.rows.forEach(function (row) {
        var line = el("tr");
        line.appendChild(el("th", {}, row.name));
        row.values.forEach(function (v, k) {
          line.appendChild(el("td", {"data-run": String(k)}, number(v)));
          if (k) {
            var big = row.percent[k] !== null && Math.abs(row.percent[k]) >= 5;
            line.appendChild(el("td", {"class": "difference", "data-run": String(k)}, signed(row.difference[k])));
            line.appendChild(el("td", {"class": big ? "difference big" : "difference", "data-run": String(k)},
                                row.percent[k] === null ? "\u2013" : (row.percent[k] > 0 ? "+" : "") + row.percent[k].toFixed(2)));
          }
          ++cells;
        });
        table.appendChild(line);
      });
      container.appendChild(table);
      check.tables.push({id: t.id, rows: t.rows.length, cells: cells});
    });
    if (data.unshared.length) {
      var list = el("details", {"class": "compare-unshared"});
      list.appendChild(el("summary", {}, "Columns not shared: " + data.unshared.length + " timeseries columns are not in every run (not overlaid)"));
      list.appendChild(el("p", {}, data.unshared.join("; ")));
      box.appendChild(list);
    }

    // The time histories, a line per run.
    box.appendChild(el("h2", {}, "Time histories (a line per run)"));
    if (typeof window.uPlot !== "function") {
      box.appendChild(el("p", {"class": "no-library"}, "This railcrash was built without its plotting library: the charts are left out."));
    } else {
      var groups = {displacement: "Car bodies: displacement", velocity: "Car bodies: velocity", force: "Crash elements: force",
                    deformation: "Crash elements: deformation", energy: "Energy partition"};
      var grids = {};
      data.charts.forEach(function (c) {
        var kind = c.id.split(":")[0];
        if (!grids[kind]) {
          box.appendChild(el("h3", {}, groups[kind] || kind));
          grids[kind] = el("div", {"class": "compare-grid"});
          box.appendChild(grids[kind]);
        }
        var largest = 0;
        c.series.forEach(function (s) { s.values.forEach(function (v) { if (v !== null && Math.abs(v) > largest) largest = Math.abs(v); }); });
        var unit = c.unit, factor = 1;
        if ((unit === "N" || unit === "J") && largest >= 1e6) { unit = "M" + unit; factor = 1e-6; }
        else if ((unit === "N" || unit === "J") && largest >= 1e3) { unit = "k" + unit; factor = 1e-3; }
        else if ((unit === "m" || unit === "m/s") && largest > 0 && largest < 1) { unit = "m" + unit; factor = 1e3; }
        var series = [{label: "t [s]"}], columns = [c.t];
        c.series.forEach(function (s, k) {
          series.push({label: s.name, stroke: colours[k % colours.length], width: 1.25, spanGaps: true, show: s.present});
          columns.push(s.values);
        });
        var plotBox = el("div", {"class": "plot"});
        grids[kind].appendChild(plotBox);
        try {
          var u = new uPlot({title: c.title, width: 440, height: 250, scales: {x: {time: false}}, series: series,
                             axes: [{label: "t [s]", values: tickLabels(1)}, {label: unit, size: 60, values: tickLabels(factor)}],
                             legend: {live: true}, cursor: {sync: {key: "railcrash-compare"}}}, columns, plotBox);
          var points = 0;
          columns.slice(1).forEach(function (col) { col.forEach(function (v) { if (v !== null) ++points; }); });
          check.charts.push({id: c.id, series: c.series.length, points: points, drawn: !!u.ctx});
        } catch (e) {
          window.railcrashErrors.push("chart " + c.id + ": " + e.message);
        }
      });
    }
    document.getElementById("footer").textContent = "railcrash report of " + n + " runs side by side (" + (data.library || "no plotting library") + ")";
    check.errors = window.railcrashErrors;
    var selfCheck = document.getElementById("self-check");
    selfCheck.textContent = JSON.stringify(check);
    selfCheck.setAttribute("data-status", window.railcrashErrors.length ? "errors" : "ran");
  }

  if (data.compare) { compareReport(); return; }
  if (data.study) { studyReport(); return; }

  // ---------------------------------------------------------------- header and problems
  var units = (summary && summary.units) || {};
  var lengthUnit = units.length || (model && model.units && model.units.length) || "";
  var forceUnit = units.force || (model && model.units && model.units.force) || "";
  var energyUnit = units.energy || (model && model.units && model.units.energy) || "";
  (function header() {
    var box = document.getElementById("problems");
    if (summary && summary.status === "failed" && !problems.some(function (p) { return p.indexOf("The run FAILED") === 0; }))
      problems.unshift("The run FAILED at t = " + fmt(summary.t_reached) + " s: " + summary.message);
    problems.forEach(function (p) {
      var failed = p.indexOf("The run FAILED") === 0 || p.indexOf("no summary.json") === 0;
      box.appendChild(el("div", {"class": failed ? "problem failed" : "problem"}, p));
    });

    var head = document.getElementById("header");
    head.textContent = "";
    head.appendChild(el("h1", {}, "railcrash run report: " + ((summary && summary.model) || (model && model.name) || data.run_dir || "")));
    var table = el("table", {"class": "facts"});
    function row(name, value, cls) {
      var tr = el("tr");
      tr.appendChild(el("th", {}, name));
      var td = el("td", cls ? {"class": cls} : {}, value);
      tr.appendChild(td);
      table.appendChild(tr);
    }
    row("run folder", data.run_dir);
    if (summary) {
      var s = summary.stats || {};
      row("status", summary.status + (summary.message ? ": " + summary.message : ""), summary.status === "ok" ? "status-ok" : "status-failed");
      row("integrator", summary.integrator);
      var used = summary.integrator_used;  // integrator auto: which method ran when, and why
      if (used) {
        var span = used.euler_from_t === null || used.euler_from_t === undefined ? ""
          : ", Euler from t = " + fmt(used.euler_from_t) + " s" +
            (used.euler_until_t === null || used.euler_until_t === undefined ? " to the end" : " to " + fmt(used.euler_until_t) + " s");
        row("method used", used.method + span + ": " + used.reason);
      }
      row("t reached", fmt(summary.t_reached) + " s");
      row("wall time, steps, events", fmt(s.wall_seconds, 3) + " s, " + s.steps + " steps, " + s.events + " events");
      var e = summary.energy || {};
      row("integration drift (energy lost)", fmt(e.integration_drift !== undefined ? e.integration_drift : -e.balance_error, 3) + " " + energyUnit + " (" + fmt(-100 * (e.relative_balance_error || 0), 3) + " % of the energy turned over; no element's dissipation)");
      var r = summary.responses;
      if (r) {
        row("R1 (crush), R2 (override), R3", fmt(r.R1) + ", " + fmt(r.R2) + ", " + fmt(r.R3));
        row("override", r.override ? "YES, at t = " + fmt(r.override_time) + " s" : "no");
      } else {
        row("R1-R3", "not computed (the model has no responses section)");
      }
      var pa = summary.peak_accelerations || {};
      var filter = pa.filter || {};
      var crush = summary.car_crush || {};
      if (summary.cars_note) row("cars", summary.cars_note);
      Object.keys(crush).forEach(function (car) {
        var parts = ["crush " + fmt(crush[car].max_crush) + " " + lengthUnit + " at t = " + fmt(crush[car].t) + " s"];
        var bodies = pa.bodies || {};
        (crush[car].bodies || []).forEach(function (b) {  // the bodies that declare this car
          if (!bodies[b] || b.indexOf("body") < 0) return;
          var p = bodies[b];
          var filtered = p.x_cfc ? fmt(p.x_cfc.g, 3) + " g" : "-";
          var mean = p.collision ? fmt(p.collision.mean_deceleration_g, 3) + " g" : "-";
          parts.push(b + ": peak x'' " + filtered + " (CFC " + fmt(filter.cfc) + "), mean deceleration " + mean);
        });
        row(car, parts.join("; "));
      });
      // Contacts and crush (summary.json "peaks": signed max and min, README "Peaks"): for a
      // penetration, crush, compression or horizontal deformation the largest value (the deepest
      // press; a negative smallest value is an opening); for a gap the smallest (the closest
      // approach; negative: the faces pressed together).
      var peaks = summary.peaks || {};
      Object.keys(peaks).forEach(function (name) {
        var quantity = name.slice(name.lastIndexOf(".") + 1);
        var p = peaks[name];
        if (p.max === null || p.min === null) return;
        if (["penetration", "crush", "compression", "horizontal_deformation"].indexOf(quantity) >= 0) {
          row(name, "largest " + fmt(p.max) + " " + lengthUnit + " at t = " + fmt(p.t_max) + " s" +
              (p.min < 0 ? " (open by up to " + fmt(-p.min) + " " + lengthUnit + ", t = " + fmt(p.t_min) + " s)" : ""));
        } else if (quantity === "gap") {
          row(name, "smallest " + fmt(p.min) + " " + lengthUnit + " at t = " + fmt(p.t_min) + " s" +
              " (largest " + fmt(p.max) + " " + lengthUnit + ", t = " + fmt(p.t_max) + " s)");
        }
      });
      var sc = summary.scenario;
      if (sc) {  // EN 15227 criteria (results/scenario_criteria.hpp): one row per criterion and subject
        row(sc.standard + " scenario " + sc.number + " (" + sc.category + ")",
            (sc.pass ? "PASS" : "FAIL") + ": every criterion below" +
            ((sc.criteria || []).some(function (c) { return c.note; }) ? " (see the notes below)" : "") +
            "; closing speed " + fmt(sc.closing_speed) + " " + lengthUnit + "/s",
            sc.pass ? "status-ok" : "status-failed");
        (sc.criteria || []).forEach(function (c) {
          var g = c.criterion === "mean_deceleration";
          // wheel unloading is (Q0 - Q) / Q0, a fraction of the static wheel load (results/scenario_criteria.hpp), not a length
          var unit = g ? " g" : c.criterion === "wheel_unloading" ? " of the static wheel load" : " " + lengthUnit;
          var value = g ? c.value_g : c.value, limit = g ? c.limit_g : c.limit;
          row(c.criterion.replace(/_/g, " ") + ": " + c.subject,
              (c.pass ? "pass" : "FAIL") + ": " + fmt(value, 4) + unit + " (limit " + fmt(limit, 4) + unit + ", margin " + fmt(limit - value, 4) + unit + ")" +
              (c.note ? "; " + c.note : ""), c.pass ? "status-ok" : "status-failed");
        });
      }
    }
    head.appendChild(table);
    // Provenance (results/provenance.hpp): which program, model files and settings made the run.
    var pv = summary && summary.provenance;
    if (pv) {
      var block = el("details", {"class": "provenance", "id": "provenance", "open": ""});
      block.appendChild(el("summary", {}, "Provenance: run " + pv.run_id));
      var list = el("table", {"class": "facts provenance-table"});
      function line(name, value) {
        var tr = el("tr");
        tr.appendChild(el("th", {}, name));
        tr.appendChild(el("td", {}, value));
        list.appendChild(tr);
      }
      line("run id", pv.run_id);
      line("program", "railcrash " + pv.version + (pv.commit ? " (commit " + pv.commit + ")" : " (not built from a git checkout)"));
      line("command line", pv.command_line || "(not run from the command line)");
      (pv.model_files || []).forEach(function (f, k) {
        line(k === 0 ? "model file" : "variant's base", f.path + "  sha256 " + f.sha256);
      });
      line("settings", (pv.settings || []).length ? pv.settings.join(", ") : "none over the model file");
      var sim = pv.simulation || {};
      line("simulation", Object.keys(sim).map(function (k) { return k + " " + sim[k]; }).join(", "));
      block.appendChild(list);
      head.appendChild(block);
    }
  })();

  // ---------------------------------------------------------------- animation
  var frames = data.frames;
  var canvas = document.getElementById("canvas");
  var ctx = canvas.getContext("2d");
  var slider = document.getElementById("slider");
  var timeLabel = document.getElementById("time-label");
  var frameIndex = 0;
  var view = null;  // {scale [px/length], x0, y0 (world at canvas centre)}
  var bodyIndex = {};
  var hulls = [];
  var elements = (model && model.elements) || [];
  var forcePeak = [];
  var events = data.events || [];
  var eventsByElement = {};
  events.forEach(function (ev, k) {
    (eventsByElement[ev[1]] = eventsByElement[ev[1]] || []).push(k);
  });

  function hull(points) {  // convex hull (monotone chain) of [[x, y], ...]
    var p = points.slice().sort(function (a, b) { return a[0] - b[0] || a[1] - b[1]; });
    if (p.length < 3) return p;
    function cross(o, a, b) { return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]); }
    var lower = [], upper = [];
    p.forEach(function (q) {
      while (lower.length >= 2 && cross(lower[lower.length - 2], lower[lower.length - 1], q) <= 0) lower.pop();
      lower.push(q);
    });
    for (var i = p.length - 1; i >= 0; --i) {
      while (upper.length >= 2 && cross(upper[upper.length - 2], upper[upper.length - 1], p[i]) <= 0) upper.pop();
      upper.push(p[i]);
    }
    return lower.slice(0, -1).concat(upper.slice(0, -1));
  }

  function pose(frame, body) {
    var k = bodyIndex[body];
    if (k === undefined) return null;
    var q = frames.pose[frame];
    return [q[3 * k], q[3 * k + 1], q[3 * k + 2]];
  }
  function place(frame, body, at) {  // global position of a body-fixed point (ground: at is global)
    if (body < 0) return at;
    var q = pose(frame, model.bodies[body].name);
    if (!q) return null;
    var c = Math.cos(q[2]), s = Math.sin(q[2]);
    return [q[0] + c * at[0] - s * at[1], q[1] + s * at[0] + c * at[1]];
  }

  var haveAnimation = frames && frames.t && frames.t.length > 0 && model && model.bodies;
  if (haveAnimation) {
    frames.bodies.forEach(function (name, k) { bodyIndex[name] = k; });
    var thinBodies = 0, thinnest = Infinity;
    model.bodies.forEach(function (b) {
      var h = hull(b.points.concat([[0, 0]]));  // with the centre of mass: no flat outline of collinear points
      // A long, flat outline (a multiple unit's car body: points along its underframe and at its
      // bogie pivots, 0.9 m high over 24 m) would show as a sliver: such a body is drawn as the
      // box around its outline, made kMinBodyAspect of its length high about the outline's middle.
      var kMinBodyAspect = 0.15;
      var xs = h.map(function (p) { return p[0]; }), ys = h.map(function (p) { return p[1]; });
      var length = Math.max.apply(null, xs) - Math.min.apply(null, xs);
      var height = Math.max.apply(null, ys) - Math.min.apply(null, ys);
      if (length > 0 && height < kMinBodyAspect * length) {
        var x0 = Math.min.apply(null, xs), x1 = Math.max.apply(null, xs);
        var ym = 0.5 * (Math.max.apply(null, ys) + Math.min.apply(null, ys)), half = 0.5 * kMinBodyAspect * length;
        h = [[x0, ym - half], [x1, ym - half], [x1, ym + half], [x0, ym + half]];
        ++thinBodies;
        height = 2 * half;
      }
      if (length > 0) thinnest = Math.min(thinnest, height / length);
      hulls.push(h);
    });
    check.body_outlines = {bodies: model.bodies.length, drawn_as_boxes: thinBodies, thinnest_height_per_length: thinnest};
    elements.forEach(function (e, k) {
      var values = frames.force[k];
      var peak = 0;
      if (values) values.forEach(function (v) { if (v !== null && Math.abs(v) > peak) peak = Math.abs(v); });
      forcePeak.push(peak);
    });
    slider.max = String(frames.t.length - 1);
  } else {
    ctx.font = "16px sans-serif";
    ctx.fillText("No animation: the run folder has no model.json (or no rows).", 20, 40);
  }

  function fitView() {
    var xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    [0, frames.t.length - 1].forEach(function (f) {
      model.bodies.forEach(function (b, i) {
        hulls[i].forEach(function (p) {
          var g = place(f, i, p);
          if (!g) return;
          xmin = Math.min(xmin, g[0]); xmax = Math.max(xmax, g[0]);
          ymin = Math.min(ymin, g[1]); ymax = Math.max(ymax, g[1]);
        });
      });
    });
    if (!isFinite(xmin)) { xmin = -1; xmax = 1; ymin = -1; ymax = 1; }
    var w = Math.max(xmax - xmin, 1e-9), h = Math.max(ymax - ymin, 1e-9);
    var scale = 0.92 * Math.min(canvas.width / w, canvas.height / h);
    view = {scale: scale, x0: 0.5 * (xmin + xmax), y0: 0.5 * (ymin + ymax)};
  }
  // Follow a car (issue 39 item 4): a long train fitted whole is a strip a few pixels high; the
  // "follow" list zooms to one car (its bodies' outline over 70 % of the canvas width) and
  // keeps it centred at every frame, the rail's sleepers passing underneath. The wheel still zooms.
  var followCar = "";
  function carBox(f, car) {  // bounding box of a car's bodies at frame f
    var box = {xmin: Infinity, xmax: -Infinity, ymin: Infinity, ymax: -Infinity};
    model.bodies.forEach(function (b, i) {
      if (b.car !== car) return;
      hulls[i].forEach(function (p) {
        var g = place(f, i, p);
        if (!g) return;
        box.xmin = Math.min(box.xmin, g[0]); box.xmax = Math.max(box.xmax, g[0]);
        box.ymin = Math.min(box.ymin, g[1]); box.ymax = Math.max(box.ymax, g[1]);
      });
    });
    return isFinite(box.xmin) ? box : null;
  }
  function followView(f, keepScale) {
    var box = carBox(f, followCar);
    if (!box) return;
    var w = Math.max(box.xmax - box.xmin, 1e-9), h = Math.max(box.ymax - Math.min(box.ymin, 0), 1e-9);
    var scale = keepScale && view ? view.scale : Math.min(0.7 * canvas.width / w, 0.8 * canvas.height / h);
    view = {scale: scale, x0: 0.5 * (box.xmin + box.xmax), y0: 0.5 * (box.ymax + Math.min(box.ymin, 0))};
  }
  // The rail: the line y = 0 (top of rail) with sleepers every 0.6 m (24 in), drawn when they are
  // at least 4 pixels apart, so that a followed car is seen to move along the track.
  var sleeperSpacing = model && model.units && model.units.length === "in" ? 24 : 0.6;
  function drawRail() {
    var y = canvas.height / 2 + view.y0 * view.scale;  // screen y of world y = 0
    ctx.strokeStyle = "#555";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(0, y); ctx.lineTo(canvas.width, y);
    ctx.stroke();
    ctx.lineWidth = 1;
    var step = sleeperSpacing * view.scale;
    if (!(step >= 4)) return;
    var first = Math.ceil((view.x0 - canvas.width / 2 / view.scale) / sleeperSpacing);
    var last = Math.floor((view.x0 + canvas.width / 2 / view.scale) / sleeperSpacing);
    ctx.strokeStyle = "#a08060";
    ctx.lineWidth = Math.max(1, Math.min(6, 0.25 * step));
    ctx.beginPath();
    for (var k = first; k <= last && k - first < 5000; ++k) {
      var x = canvas.width / 2 + (k * sleeperSpacing - view.x0) * view.scale;
      ctx.moveTo(x, y + 1); ctx.lineTo(x, y + Math.max(3, Math.min(10, 0.3 * step)));
    }
    ctx.stroke();
    ctx.lineWidth = 1;
  }
  function toScreen(p) {
    return [canvas.width / 2 + (p[0] - view.x0) * view.scale, canvas.height / 2 - (p[1] - view.y0) * view.scale];
  }
  // Walls and barriers (issue 39 item 4): a contact element's ground surface from model.json,
  // a line (a wall) drawn across the canvas with hatching on its solid side, or a circle (a
  // barrier face) with its solid side shaded. drawnSurfaces: what the last frame drew, for the self-check.
  var drawnSurfaces = [];
  function drawSurfaces() {
    drawnSurfaces = [];
    var reach = (canvas.width + canvas.height) / view.scale;  // [length] longer than the canvas's diagonal
    elements.forEach(function (e) {
      var g = e.surface;
      if (!g) return;
      ctx.save();
      ctx.strokeStyle = "#333";
      ctx.fillStyle = "rgba(90,90,90,0.25)";
      ctx.lineWidth = 3;
      if (g.kind === "line") {
        var n = g.normal, d = [-n[1], n[0]];  // along the line
        var a = toScreen([g.point[0] - reach * d[0], g.point[1] - reach * d[1]]);
        var b = toScreen([g.point[0] + reach * d[0], g.point[1] + reach * d[1]]);
        ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
        // The solid side (against the normal), shaded 12 px deep, hatched every 10 px.
        var depth = 12, sn = [-n[0] * depth, n[1] * depth];  // screen offset into the solid (screen y down)
        ctx.beginPath();
        ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.lineTo(b[0] + sn[0], b[1] + sn[1]); ctx.lineTo(a[0] + sn[0], a[1] + sn[1]);
        ctx.closePath(); ctx.fill();
        ctx.lineWidth = 1;
        var length = Math.hypot(b[0] - a[0], b[1] - a[1]), ux = (b[0] - a[0]) / length, uy = (b[1] - a[1]) / length;
        ctx.beginPath();
        for (var s = 0; s < length && s < 20000; s += 10) {
          var x = a[0] + ux * s, y = a[1] + uy * s;
          ctx.moveTo(x, y); ctx.lineTo(x + sn[0] + ux * 6, y + sn[1] + uy * 6);
        }
        ctx.stroke();
        var p = toScreen(g.point);
        drawnSurfaces.push({element: e.name, kind: "line", point_px: p,
                            on_canvas: p[0] >= 0 && p[0] <= canvas.width && p[1] >= 0 && p[1] <= canvas.height});
      } else if (g.kind === "circle") {
        var c = toScreen(g.center), r = g.radius * view.scale;
        ctx.beginPath(); ctx.arc(c[0], c[1], r, 0, 2 * Math.PI);
        if (!g.inside) ctx.fill();  // outside contact: the solid is the circle
        ctx.stroke();
        var gap = Math.hypot(c[0] - canvas.width / 2, c[1] - canvas.height / 2);
        drawnSurfaces.push({element: e.name, kind: "circle", center_px: c, radius_px: r,
                            on_canvas: gap - r < Math.hypot(canvas.width, canvas.height) / 2 && gap + r > 0});
      }
      ctx.restore();
    });
  }

  function modeOf(elementName, t) {  // category from the element's last event up to t
    var list = eventsByElement[elementName];
    if (!list) return "none";
    var text = null;
    for (var i = 0; i < list.length && events[list[i]][0] <= t + 1e-12; ++i) text = events[list[i]][2].toLowerCase();
    if (text === null) return "none";
    if (/fail|ruptur|fractur|shear|broke|overrid/.test(text)) return "failed";
    if (/plastic|yield|bottom|crush|lock/.test(text)) return "plastic";
    if (/open|separat|lost|lift|release/.test(text)) return "open";
    return "elastic";
  }
  var modeColours = {none: "#8a8a8a", elastic: "#1f77b4", plastic: "#ff7f0e", failed: "#d62728", open: "#bbbbbb"};
  function forceColour(fraction) {  // light grey (no force) to dark red (the element's peak)
    var f = Math.max(0, Math.min(1, fraction));
    var r = Math.round(200 + 55 * f), g = Math.round(200 * (1 - f)), b = Math.round(200 * (1 - f));
    return "rgb(" + r + "," + g + "," + b + ")";
  }

  function draw(f) {
    if (!haveAnimation) return;
    if (followCar) followView(f, !!view);
    if (!view) fitView();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    drawRail();
    drawSurfaces();
    model.bodies.forEach(function (b, i) {
      var pts = hulls[i].map(function (p) { return place(f, i, p); });
      if (pts.some(function (p) { return !p; })) return;
      ctx.beginPath();
      pts.forEach(function (p, k) { var s = toScreen(p); if (k) ctx.lineTo(s[0], s[1]); else ctx.moveTo(s[0], s[1]); });
      ctx.closePath();
      ctx.fillStyle = followCar && b.car === followCar ? "rgba(240,170,60,0.45)"
                      : b.name.indexOf("car2") === 0 ? "rgba(120,160,220,0.35)" : "rgba(150,200,150,0.35)";
      ctx.fill();
      ctx.strokeStyle = "#555";
      ctx.lineWidth = 1;
      ctx.stroke();
      var c = toScreen(place(f, i, [0, 0]));
      ctx.fillStyle = "#333";
      ctx.fillRect(c[0] - 1.5, c[1] - 1.5, 3, 3);
    });
    var byMode = document.getElementById("colour-by").value === "mode";
    var t = frames.t[f];
    elements.forEach(function (e, k) {
      var pts = e.points.map(function (p) { return place(f, p.body, p.at); });
      if (pts.some(function (p) { return !p; })) return;
      var colour;
      if (byMode) {
        colour = modeColours[modeOf(e.name, t)];
      } else {
        var v = frames.force[k] ? frames.force[k][f] : null;
        colour = v === null || forcePeak[k] === 0 ? "#8a8a8a" : forceColour(Math.abs(v) / forcePeak[k]);
      }
      ctx.strokeStyle = colour;
      ctx.fillStyle = colour;
      ctx.lineWidth = e.constraint ? 1.5 : 2.5;
      if (pts.length === 1) {
        var s = toScreen(pts[0]);
        ctx.beginPath(); ctx.arc(s[0], s[1], 3, 0, 2 * Math.PI); ctx.fill();
        return;
      }
      ctx.beginPath();
      pts.forEach(function (p, j) { var s = toScreen(p); if (j) ctx.lineTo(s[0], s[1]); else ctx.moveTo(s[0], s[1]); });
      ctx.stroke();
    });
    ctx.fillStyle = "#222";
    ctx.font = "14px sans-serif";
    ctx.fillText("t = " + fmt(t, 5) + " s", 10, 20);
  }

  var eventRows = [];
  (function eventLog() {
    var log = document.getElementById("event-log");
    events.forEach(function (ev) {
      var row = el("div", {}, fmt(ev[0], 5) + " s  " + ev[1] + ": " + ev[2]);
      row.title = ev[1] + ": " + ev[2] + " (value " + fmt(ev[3]) + ")";
      row.addEventListener("click", function () { setFrame(nearestFrame(ev[0])); });
      log.appendChild(row);
      eventRows.push(row);
    });
    if (!events.length) log.appendChild(el("div", {}, "no events"));
  })();
  function nearestFrame(t) {
    if (!haveAnimation) return 0;
    var best = 0;
    for (var i = 0; i < frames.t.length; ++i) if (Math.abs(frames.t[i] - t) < Math.abs(frames.t[best] - t)) best = i;
    return best;
  }
  var lastCurrent = null;
  function syncEvents(t) {
    var current = null;
    eventRows.forEach(function (row, k) {
      var past = events[k][0] <= t + 1e-12;
      row.className = past ? "past" : "future";
      if (past) current = row;
    });
    if (current) {
      current.className = "current";
      if (current !== lastCurrent) {
        var log = document.getElementById("event-log");
        log.scrollTop = Math.max(0, current.offsetTop - log.offsetTop - 150);
      }
    }
    lastCurrent = current;
  }
  var plotsToMark = [];
  function setFrame(f) {
    if (!haveAnimation) return;
    frameIndex = Math.max(0, Math.min(frames.t.length - 1, f));
    slider.value = String(frameIndex);
    timeLabel.textContent = "t = " + fmt(frames.t[frameIndex], 5) + " s (" + (frameIndex + 1) + "/" + frames.t.length + ")";
    draw(frameIndex);
    syncEvents(frames.t[frameIndex]);
    plotsToMark.forEach(function (u) { u.redraw(false, false); });
  }

  var playing = false, lastTime = null, simTime = 0;
  function step(now) {
    if (!playing) return;
    if (lastTime !== null) {
      simTime += (now - lastTime) / 1000 * Number(document.getElementById("speed").value);
      var f = frameIndex;
      while (f + 1 < frames.t.length && frames.t[f + 1] <= simTime) ++f;
      if (f >= frames.t.length - 1) { setFrame(frames.t.length - 1); togglePlay(); return; }
      if (f !== frameIndex) setFrame(f);
    }
    lastTime = now;
    requestAnimationFrame(step);
  }
  function togglePlay() {
    playing = !playing && haveAnimation;
    document.getElementById("play").textContent = playing ? "Pause" : "Play";
    if (playing) {
      if (frameIndex >= frames.t.length - 1) frameIndex = 0;
      simTime = frames.t[frameIndex];
      lastTime = null;
      requestAnimationFrame(step);
    }
  }
  document.getElementById("play").addEventListener("click", togglePlay);
  slider.addEventListener("input", function () { setFrame(Number(slider.value)); });
  document.getElementById("colour-by").addEventListener("change", function () { draw(frameIndex); legend(); });
  document.getElementById("reset-view").addEventListener("click", function () { view = null; draw(frameIndex); });
  var followSelect = document.getElementById("follow");
  var carNames = [];
  if (haveAnimation) model.bodies.forEach(function (b) { if (b.car && carNames.indexOf(b.car) < 0) carNames.push(b.car); });
  carNames.forEach(function (car) { followSelect.appendChild(el("option", {value: car}, car)); });
  if (!carNames.length) document.getElementById("follow-label").hidden = true;
  followSelect.addEventListener("change", function () { followCar = followSelect.value; view = null; draw(frameIndex); });
  var followAsked = /^#follow=(.+)$/.exec(location.hash);  // report.html#follow=CAR: opens following CAR
  function followFromAddress() {
    if (!followAsked || carNames.indexOf(decodeURIComponent(followAsked[1])) < 0) return;
    followSelect.value = followCar = decodeURIComponent(followAsked[1]);
    view = null;
    draw(frameIndex);
  }
  canvas.addEventListener("wheel", function (e) {
    if (!view) return;
    e.preventDefault();
    var rect = canvas.getBoundingClientRect();
    var sx = (e.clientX - rect.left) * canvas.width / rect.width, sy = (e.clientY - rect.top) * canvas.height / rect.height;
    var wx = view.x0 + (sx - canvas.width / 2) / view.scale, wy = view.y0 - (sy - canvas.height / 2) / view.scale;
    var factor = e.deltaY < 0 ? 1.2 : 1 / 1.2;
    view.scale *= factor;
    view.x0 = wx - (sx - canvas.width / 2) / view.scale;
    view.y0 = wy + (sy - canvas.height / 2) / view.scale;
    draw(frameIndex);
  }, {passive: false});
  var drag = null;
  canvas.addEventListener("mousedown", function (e) { drag = [e.clientX, e.clientY]; });
  window.addEventListener("mouseup", function () { drag = null; });
  window.addEventListener("mousemove", function (e) {
    if (!drag || !view) return;
    view.x0 -= (e.clientX - drag[0]) / view.scale;
    view.y0 += (e.clientY - drag[1]) / view.scale;
    drag = [e.clientX, e.clientY];
    draw(frameIndex);
  });
  function legend() {
    var box = document.getElementById("legend");
    box.textContent = "";
    if (document.getElementById("colour-by").value === "mode") {
      box.appendChild(document.createTextNode("Element colour: mode after its last event:"));
      Object.keys(modeColours).forEach(function (m) {
        var sw = el("span", {"class": "swatch"});
        sw.style.background = modeColours[m];
        box.appendChild(sw);
        box.appendChild(document.createTextNode(m === "none" ? "no event yet" : m));
      });
    } else {
      box.appendChild(document.createTextNode("Element colour: |force| / its peak over the run, grey (0) to red (peak); " +
                                              "thin lines: joints. Bodies: polygons of their connection points (a long, flat one: a box 0.15 of its length high). Length unit: " + lengthUnit));
    }
  }
  legend();

  // ---------------------------------------------------------------- plots
  var haveLibrary = typeof window.uPlot === "function";
  var drawnPlots = [];  // {id, u}: their tick labels go into the self-check
  // The crush zones of summary.json (results/crush_zones.hpp): their declared curves under the loops, their energies.
  var crushZones = (summary && summary.crush_zones) || null;
  var zoneByName = {};
  ((crushZones && crushZones.zones) || []).forEach(function (z) { zoneByName[z.element] = z; });
  var palette = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
  function timeMarker(u) {  // the animation's time as a vertical line
    if (!haveAnimation) return;
    var x = u.valToPos(frames.t[frameIndex], "x", true);
    var c = u.ctx;
    c.save();
    c.strokeStyle = "rgba(0,0,0,0.45)";
    c.setLineDash([4, 3]);
    c.beginPath();
    c.moveTo(x, u.bbox.top);
    c.lineTo(x, u.bbox.top + u.bbox.height);
    c.stroke();
    c.restore();
  }
  function unitOf(label) {
    return {length: lengthUnit, "length/time": lengthUnit ? lengthUnit + "/s" : "", force: forceUnit, energy: energyUnit, g: "g"}[label] || label;
  }
  // ---------------------------------------------------------------- readable axes
  // SI prefixes (kN, MN, kJ, MJ, mm; kip for lbf) chosen from the largest value shown; tick labels with as
  // many decimals as the tick spacing needs, so that no two ticks read the same.
  var siUnits = {N: true, J: true, "N*m": true, m: true, "m/s": true, Pa: true};
  function scaledUnit(unit, largest) {
    if ((unit === "lbf" || unit === "in*lbf") && largest >= 1e4)  // US customary: kip = 1000 lbf
      return {unit: unit === "lbf" ? "kip" : "kip*in", factor: 1e-3};
    if (!siUnits[unit] || !(largest > 0)) return {unit: unit, factor: 1};
    if (unit === "m" || unit === "m/s") return largest < 1 ? {unit: "m" + unit, factor: 1e3} : {unit: unit, factor: 1};
    if (largest >= 1e9) return {unit: "G" + unit, factor: 1e-9};
    if (largest >= 1e6) return {unit: "M" + unit, factor: 1e-6};
    if (largest >= 1e3) return {unit: "k" + unit, factor: 1e-3};
    return {unit: unit, factor: 1};
  }
  function largestOf(columns) {
    var largest = 0;
    columns.forEach(function (c) { (c || []).forEach(function (v) { if (v !== null && isFinite(v) && Math.abs(v) > largest) largest = Math.abs(v); }); });
    return largest;
  }
  function tickLabels(factor) {  // uPlot axis `values`: distinct labels at the ticks' spacing
    return function (u, splits) {
      var step = Infinity;
      for (var i = 1; i < splits.length; ++i) step = Math.min(step, Math.abs(splits[i] - splits[i - 1]) * factor);
      var decimals = isFinite(step) && step > 0 ? Math.max(0, Math.min(12, Math.ceil(-Math.log10(step) - 1e-9))) : 3;
      while (decimals < 12 && isFinite(step) && step > 0 &&  // a spacing of 2.5 needs one decimal more than 2
             Math.abs(step * Math.pow(10, decimals) - Math.round(step * Math.pow(10, decimals))) > 1e-6 * step * Math.pow(10, decimals)) ++decimals;
      return splits.map(function (v) {
        if (v === null || v === undefined) return "";
        var text = (v * factor).toFixed(decimals);
        return /^-0(\.0*)?$/.test(text) ? text.slice(1) : text;
      });
    };
  }
  window.railcrashTickLabels = tickLabels;  // (the browser test checks the labels)
  function readableAxis(label, unit, largest, extra) {  // a y axis with its unit scaled
    var s = scaledUnit(unit, largest);
    var axis = {label: label ? label + (s.unit ? " [" + s.unit + "]" : "") : s.unit, size: 70, values: tickLabels(s.factor)};
    for (var k in extra || {}) axis[k] = extra[k];
    return axis;
  }

  function addTimePlot(container, spec, extra) {
    var box = el("div", {"class": "plot"});
    container.appendChild(box);
    var series = [{label: "t [s]"}];
    var columns = [spec.t];
    spec.series.forEach(function (s, k) {
      series.push({label: s.name, show: s.show, stroke: palette[k % palette.length], width: 1.25, spanGaps: false});
      columns.push(s.values);
    });
    var options = {
      title: spec.title, width: 560, height: 320,
      scales: {x: {time: false}},
      axes: [{label: "t [s]", values: tickLabels(1)}, readableAxis("", unitOf(spec.y_label), largestOf(columns.slice(1)))],
      series: series,
      legend: {live: true},
      cursor: {sync: {key: "railcrash-time"}},
      hooks: {draw: [timeMarker]}
    };
    if (extra) extra(options, columns);
    var u = new uPlot(options, columns, box);
    plotsToMark.push(u);
    drawnPlots.push({id: spec.id, u: u});
    var notes = [];
    if (spec.note) notes.push(spec.note);
    if (spec.decimated) notes.push("decimated for drawing: every peak kept (min/max per bucket)");
    if (notes.length) box.appendChild(el("div", {"class": "note"}, notes.join("; ")));
    var points = 0;
    columns.slice(1).forEach(function (c) { c.forEach(function (v) { if (v !== null) ++points; }); });
    check.plots.push({id: spec.id, series: columns.length - 1, points: points, drawn: !!u.ctx});
    return u;
  }
  function noLibrary(container) {
    container.appendChild(el("p", {"class": "no-library"},
      "This railcrash was built without its plotting library (npm was not available when it was built), so the plots are " +
      "left out. Install nodejs and npm (scripts/install-deps.sh), build again and run `railcrash report` on this folder."));
  }

  var plotsBox = document.getElementById("plots");
  if (!haveLibrary) noLibrary(plotsBox);
  else (data.plots || []).forEach(function (spec) {
    if (!spec.series.length) { plotsBox.appendChild(el("p", {}, spec.title + ": nothing to plot")); return; }
    addTimePlot(plotsBox, spec);
  });

  var loopsBox = document.getElementById("loops");
  if (!haveLibrary) noLibrary(loopsBox);
  else if (!(data.loops || []).length) loopsBox.appendChild(el("p", {}, "No element with a crash force and deformation (crush springs, draft gears, anticlimbers, couplings) in this model."));
  else data.loops.forEach(function (loop) {
    var box = el("div", {"class": "plot"});
    loopsBox.appendChild(box);
    var design = designCurveSeries(loop);
    var lines = [[loop.x, loop.y]].concat(design.map(function (d) { return d.data; }));
    var xs = lines.map(function (l) { return l[0]; }), ys = lines.map(function (l) { return l[1]; });
    var u = new uPlot({
      mode: 2, title: loop.name + " (" + loop.type + ")", width: 420, height: 320,
      scales: {x: {time: false}},
      axes: [readableAxis(loop.x_label, lengthUnit, largestOf(xs), {size: 50}), readableAxis(loop.y_label, forceUnit, largestOf(ys))],
      series: [{}, {label: loop.name, stroke: "#d62728", width: 1.25, paths: uPlot.paths.linear(), points: {show: false}}].concat(
        design.map(function (d) { return {label: d.label, stroke: d.stroke, width: 1.5, dash: d.dash, paths: uPlot.paths.linear(), points: {show: false}}; })),
      legend: {show: design.length > 0, live: false}
    }, [null].concat(lines), box);
    if (design.length) box.appendChild(el("div", {"class": "note"}, "red: the run; black: the declared loading curve up to its last point (dotted: beyond it); " +
                                                                    "grey dashed: unloading from the largest deformation reached"));
    drawnPlots.push({id: "loop:" + loop.name, u: u});
    check.plots.push({id: "loop:" + loop.name, series: lines.length, points: loop.x.length, drawn: !!u.ctx, design: design.length});
  });

  // ---------------------------------------------------------------- crush zones: declared curves and absorbed energy
  function designCurveSeries(loop) {  // the declared loading curve and unloading line(s) of a loop's element
    var zone = zoneByName[loop.name];
    if (!zone || !zone.curve) return [];
    var c = zone.curve, out = [{label: "declared loading curve", stroke: "#111", dash: undefined, data: [c.deformation.slice(), c.force.slice()]}];
    function onCurve(d) {  // the loading curve at d (its last slope beyond its last point)
      var x = c.deformation, y = c.force, n = x.length;
      if (c.beyond_last_slope !== undefined && d > x[n - 1]) return y[n - 1] + c.beyond_last_slope * (d - x[n - 1]);
      if (n === 1) return y[0];
      var k = 0;
      while (k + 2 < n && d > x[k + 1]) ++k;
      return y[k] + (y[k + 1] - y[k]) * (d - x[k]) / (x[k + 1] - x[k]);
    }
    var reached = 0;
    loop.x.forEach(function (d) { if (d !== null && d > reached) reached = d; });
    var last = c.deformation.length - 1;
    if (c.beyond_last_slope !== undefined && reached > c.deformation[last]) {  // on past its last point to the deformation reached
      out.push({label: c.open_ended ? "declared loading curve (no last point)" : "beyond its last point", stroke: "#111", dash: [3, 3],
                data: [[c.deformation[last], reached], [c.force[last], c.force[last] + c.beyond_last_slope * (reached - c.deformation[last])]]});
    }
    if (c.unloading_stiffness > 0 && reached > c.deformation[0]) {
      var top = onCurve(reached);
      var floor = 0;
      if (c.lower_deformation) {  // draft gear: down to its unloading curve
        var lx = c.lower_deformation, ly = c.lower_force;
        var lower = reached > lx[1] && c.beyond_last_slope !== undefined ? ly[1] + c.beyond_last_slope * (reached - lx[1])
                                                                         : ly[0] + (ly[1] - ly[0]) * (reached - lx[0]) / (lx[1] - lx[0]);
        floor = Math.max(0, Math.min(lower, top));
        out.push({label: "declared unloading curve", stroke: "#777", dash: [2, 3], data: [lx, ly]});
      }
      var back = reached - (top - floor) / c.unloading_stiffness;
      out.push({label: "unloading line", stroke: "#777", dash: [6, 4], data: [[reached, back], [top, floor]]});
    }
    return out;
  }
  (function zonesChart() {
    var box = document.getElementById("zones");
    var zones = (crushZones && crushZones.zones) || [];
    if (!crushZones) { box.appendChild(el("p", {}, "summary.json has no crush_zones (a run of an older railcrash, or no summary): no energy per crush zone.")); return; }
    if (!zones.length) { box.appendChild(el("p", {}, "No crush zone (crush spring, anticlimber, draft gear) in this model.")); return; }
    var total = crushZones.total_absorbed || 0;
    var largest = 0;
    zones.forEach(function (z) { largest = Math.max(largest, Math.abs(z.absorbed || 0), z.capacity || 0); });
    var s = scaledUnit(energyUnit, largest);
    var rowHeight = 26, left = 230, right = 330, width = 1100;
    var canvasZones = el("canvas", {width: String(width), height: String(40 + rowHeight * zones.length + 30), id: "zones-canvas"});
    box.appendChild(canvasZones);
    var c = canvasZones.getContext("2d");
    var plotWidth = width - left - right;
    var scale = largest > 0 ? plotWidth / largest : 0;
    c.font = "13px sans-serif";
    c.fillStyle = "#222";
    c.fillText("Energy absorbed [" + s.unit + "] (bar) against capacity (outline: area under the declared curve to its last point)", 10, 18);
    // Gridlines at readable ticks.
    var step = largest > 0 ? Math.pow(10, Math.floor(Math.log10(largest))) : 1;
    if (largest / step < 2.5) step /= 5; else if (largest / step < 5) step /= 2;
    var ticks = [];
    for (var v = 0; v <= largest * 1.0001; v += step) ticks.push(v);
    var labels = tickLabels(s.factor)(null, ticks);
    var bottom = 36 + rowHeight * zones.length;
    c.strokeStyle = "#e4e4e4";
    c.fillStyle = "#555";
    ticks.forEach(function (v, k) {
      var x = left + v * scale;
      c.beginPath(); c.moveTo(x, 30); c.lineTo(x, bottom); c.stroke();
      c.fillText(labels[k], x - 8, bottom + 16);
    });
    zones.forEach(function (z, k) {
      var y = 36 + k * rowHeight;
      c.fillStyle = "#222";
      var name = z.element.length > 30 ? z.element.slice(0, 29) + "…" : z.element;
      c.fillText(name, 10, y + 15);
      var absorbed = Math.max(0, z.absorbed || 0);
      var used = z.capacity > 0 ? absorbed / z.capacity : null;
      c.fillStyle = used !== null && used > 1 ? "#d62728" : "#1f77b4";
      c.fillRect(left, y + 3, absorbed * scale, rowHeight - 8);
      if (z.capacity > 0) {
        c.strokeStyle = "#111";
        c.lineWidth = 1.5;
        c.strokeRect(left, y + 3, z.capacity * scale, rowHeight - 8);
        c.lineWidth = 1;
      }
      c.fillStyle = "#222";
      var text = fmt((z.absorbed || 0) * s.factor, 3) + " " + s.unit +
                 (z.capacity > 0 ? " of " + fmt(z.capacity * s.factor, 3) + " (" + fmt(100 * used, 3) + " %)" : ", no declared capacity") +
                 (total > 0 ? "; " + fmt(100 * z.share_of_total, 3) + " % of all" : "");
      c.fillText(text, width - right + 10, y + 15);
    });
    // The numbers, per zone and per car.
    var t = el("table", {"class": "facts zones", id: "zones-table"});
    function row(cells, header) {
      var tr = el("tr");
      cells.forEach(function (cell, k) { tr.appendChild(el(header ? "th" : "td", k >= 3 ? {"class": "number"} : {}, cell)); });
      t.appendChild(tr);
    }
    row(["crush zone", "type", "cars", "absorbed [" + s.unit + "]", "dissipated [" + s.unit + "]", "recoverable [" + s.unit + "]",
         "capacity [" + s.unit + "]", "capacity used", "share of all zones"], true);
    function value(v) { return v === null || v === undefined ? "-" : fmt(v * s.factor, 4); }
    zones.forEach(function (z) {
      row([z.element, z.type, (z.cars || []).map(function (c) { return c.car + (c.share < 1 ? " (" + fmt(c.share) + ")" : ""); }).join(", ") || "-",
           value(z.absorbed), value(z.dissipated), value(z.recoverable), value(z.capacity),
           z.capacity_used === null || z.capacity_used === undefined ? "-" : fmt(100 * z.capacity_used, 3) + " %",
           z.share_of_total === null || z.share_of_total === undefined ? "-" : fmt(100 * z.share_of_total, 3) + " %"]);
    });
    var cars = crushZones.cars || {};
    Object.keys(cars).forEach(function (name) {
      var car = cars[name];
      row(["car " + name, "", "", value(car.absorbed), "", "", value(car.capacity),
           car.capacity > 0 ? fmt(100 * car.absorbed / car.capacity, 3) + " %" : "-",
           car.share_of_total === null || car.share_of_total === undefined ? "-" : fmt(100 * car.share_of_total, 3) + " %"]);
    });
    var dissipatedAll = summary.energy && summary.energy.dissipated;
    row(["all crush zones", "", "", value(total), "", "", "", "", "100 %"]);
    box.appendChild(t);
    box.appendChild(el("p", {"class": "hint"}, "absorbed: work done on the zone (dissipated + the change of its recoverable elastic energy); " +
      "dissipated in all elements of the run: " + value(dissipatedAll) + " " + s.unit + "; per car, a zone between two cars counts half for each. " +
      "The numbers are in summary.json (crush_zones) and energy_zones.csv."));
    check.plots.push({id: "energy_zones", series: zones.length, points: zones.length, drawn: true, cars: Object.keys(cars).length});
  })();

  var energyBox = document.getElementById("energy");
  if (!haveLibrary) noLibrary(energyBox);
  else if (!data.energy) energyBox.appendChild(el("p", {}, "No energy.csv in this run folder."));
  else (function energyPlot() {
    // Stacked areas: kinetic, elastic, gravity change, dissipated by element type; lines:
    // initial energy + external work (the top of the stack when the balance closes) and the
    // integration drift (energy the integration lost, attributed to no element) on its own axis.
    var spec = data.energy;
    var byName = {};
    spec.series.forEach(function (s) { byName[s.name] = s.values; });
    var layers = ["kinetic", "elastic", "gravity"];
    spec.series.forEach(function (s) { if (s.name.indexOf("dissipated.") === 0) layers.push(s.name); });
    var n = spec.t.length;
    var total0 = byName.kinetic && byName.elastic ? byName.kinetic[0] + byName.elastic[0] : 0;
    var stacked = [], sum = new Array(n).fill(0);
    var available = layers.filter(function (name) {
      var v = byName[name];
      return v && v.some(function (x) { return x !== null && Math.abs(x) > 0; });
    });
    available.forEach(function (name) {
      var v = byName[name];
      sum = sum.map(function (s, k) { return s + (v[k] || 0); });
      stacked.push(sum.slice());
    });
    var supply = byName.external_work ? byName.external_work.map(function (w) { return total0 + (w || 0); }) : null;
    var columns = [spec.t].concat(stacked);
    var series = [{label: "t [s]"}];
    var fills = ["rgba(31,119,180,0.45)", "rgba(44,160,44,0.45)", "rgba(140,86,75,0.35)", "rgba(255,127,14,0.45)",
                 "rgba(214,39,40,0.4)", "rgba(148,103,189,0.4)", "rgba(227,119,194,0.4)", "rgba(188,189,34,0.4)", "rgba(23,190,207,0.4)"];
    var bands = [];
    available.forEach(function (name, k) {
      series.push({label: name + " (stacked)", stroke: fills[k % fills.length].replace(/0\.\d+\)$/, "1)"), width: 1,
                   fill: k === 0 ? fills[0] : undefined});
      if (k > 0) bands.push({series: [k + 1, k], fill: fills[k % fills.length]});
    });
    if (supply) { columns.push(supply); series.push({label: "initial + external work", stroke: "#555", width: 1.5, dash: [8, 4]}); }
    if (byName.integration_drift) { columns.push(byName.integration_drift); series.push({label: "integration drift (right axis)", stroke: "#000", width: 1, dash: [2, 2], scale: "error"}); }
    var box = el("div", {"class": "plot"});
    energyBox.appendChild(box);
    var u = new uPlot({
      title: "Energy partition (stacked areas)", width: 900, height: 380,
      scales: {x: {time: false}, y: {range: function (u, min, max) { return [Math.min(0, min), max + 0.02 * Math.abs(max - Math.min(0, min))]; }}, error: {}},
      axes: [{label: "t [s]", values: tickLabels(1)}, readableAxis("", energyUnit, largestOf(columns.slice(1)), {size: 80}),
             {scale: "error", side: 1, label: "integration drift [" + energyUnit + "]", size: 80, grid: {show: false}, values: tickLabels(1)}],
      series: series, bands: bands, legend: {live: true},
      cursor: {sync: {key: "railcrash-time"}}, hooks: {draw: [timeMarker]}
    }, columns, box);
    plotsToMark.push(u);
    var points = 0;
    columns.slice(1).forEach(function (c) { c.forEach(function (v) { if (v !== null) ++points; }); });
    check.plots.push({id: "energy", series: columns.length - 1, points: points, drawn: !!u.ctx});
    drawnPlots.push({id: "energy", u: u});
  })();

  document.getElementById("footer").textContent = "railcrash report; plots by " + (data.library || "no plotting library") +
    " (inlined); accelerations filtered at CFC " + fmt(data.cfc) + " (SAE J211-1 / ISO 6487); " + (data.rows || 0) + " output rows.";

  // ---------------------------------------------------------------- self-check (for the browser test)
  function canvasDigest() {
    var pixels = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    var hash = 0;
    for (var i = 0; i < pixels.length; i += 7) hash = (hash * 31 + pixels[i]) % 1000000007;
    return hash;
  }
  if (haveAnimation) {
    setFrame(0);
    var first = canvasDigest();
    setFrame(frames.t.length - 1);
    var last = canvasDigest();
    check.frames = {count: frames.t.length, first: first, last: last, differ: first !== last};
    check.surfaces = drawnSurfaces;  // at the last frame, the whole model in view
    if (eventRows.length) {  // a click on the last event moves the animation to its time
      var k = eventRows.length - 1;
      eventRows[k].click();
      check.event_jump = {event_t: events[k][0], frame_t: frames.t[frameIndex],
                          spacing: frames.t.length > 1 ? frames.t[1] - frames.t[0] : 0, current: eventRows[k].className};
    }
    if (carNames.length) {  // following the first car: it stays centred and is drawn larger than the whole model
      var wholeScale = (fitView(), view.scale);
      followCar = carNames[0];
      view = null;
      var centres = [0, frames.t.length - 1].map(function (f) {
        setFrame(f);
        var b = carBox(f, followCar);
        return toScreen([0.5 * (b.xmin + b.xmax), 0])[0] - canvas.width / 2;
      });
      check.follow = {car: followCar, cars: carNames.length, offsets_px: centres, zoom: view.scale / wholeScale};
      followCar = "";
      view = null;
    }
    // The page opens at the middle of the run, or where its address asks: report.html#t=last
    // (the end: `railcrash report --pdf` prints that, the final deformed state) or #t=SECONDS.
    var timeAsked = /^#t=(last|[0-9.eE+-]+)$/.exec(location.hash);
    var opening = 0.5 * frames.t[frames.t.length - 1];
    if (timeAsked) opening = timeAsked[1] === "last" ? frames.t[frames.t.length - 1] : Number(timeAsked[1]);
    setFrame(isFinite(opening) ? nearestFrame(opening) : 0);
    check.opened = {index: frameIndex, t: frames.t[frameIndex], asked: timeAsked ? timeAsked[1] : null};
    followFromAddress();
  }
  // report.html#crush-zones: the loops and the energy per crush zone alone (docs' screenshot, printing).
  if (location.hash === "#crush-zones")
    ["problems", "provenance", "animation-section", "plots-section", "energy-section"].forEach(function (id) {
      var node = document.getElementById(id);
      if (node) node.hidden = true;
    });
  var box = document.getElementById("self-check");
  check.library = haveLibrary;
  check.problems = problems.length;
  check.errors = window.railcrashErrors;
  check.ms = Math.round(performance.now());  // from navigation start to the page drawn, self-check included
  box.textContent = JSON.stringify(check);
  box.setAttribute("data-status", window.railcrashErrors.length ? "errors" : "ran");
  // The tick labels as uPlot drew them (axes[k]._values, after its first draw): no axis may
  // show the same label twice ("0 0 0 0.001").
  setTimeout(function () {
    check.axes = drawnPlots.map(function (p) {
      var labels = p.u.axes.map(function (a) { return (a._values || []).map(String); });
      var repeated = labels.some(function (list) { return new Set(list).size !== list.length; });
      return {id: p.id, labels: labels, distinct: !repeated, y_label: p.u.axes[1] && p.u.axes[1].label};
    });
    check.errors = window.railcrashErrors;
    box.textContent = JSON.stringify(check);
    box.setAttribute("data-status", window.railcrashErrors.length ? "errors" : "ran");
  }, 100);
})();
