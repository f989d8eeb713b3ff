#!/usr/bin/env bash
# `railcrash report --pdf` (issue 39 item 7): without chromium on PATH, exit 2 saying to install
# it; with it, the report of the small two-car crash (tests/report/two_car.yaml) printed to PDF,
# turned into pages with pdftoppm and checked as a reader would see it: at least 4 pages, none
# blank, the header's text on the first, and every chart (a canvas, an image in the PDF) drawn,
# not empty. Exits 77 (CTest: skipped) with the reason when chromium or poppler-utils is absent.
# Leaves the first page in OUTPUT_DIR/report_pdf_page-1.png.
# Usage: test_report_pdf.sh RAILCRASH_BINARY SOURCE_DIR OUTPUT_DIR
set -u
bin=$1 src=$2 out=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
python=/usr/bin/python3
[ -x "$python" ] || python=python3

"$bin" run "$src/tests/report/two_car.yaml" --out "$tmp/run" --quiet > "$tmp/run.log" 2>&1 || { cat "$tmp/run.log"; fail "run"; }

# No chromium on PATH: an input error (exit 2) that says what to install; the page is written.
PATH=/nonexistent "$bin" report "$tmp/run" --pdf > "$tmp/stdout" 2> "$tmp/stderr"
status=$?
[ "$status" -eq 2 ] || fail "report --pdf without chromium: exit $status, not 2"
grep -q "no chromium on PATH" "$tmp/stderr" && grep -q "apt-get install chromium" "$tmp/stderr" ||
  { cat "$tmp/stderr"; fail "the message does not say to install chromium"; }
[ ! -e "$tmp/run/report.pdf" ] || fail "a report.pdf without chromium"

command -v chromium > /dev/null || command -v chromium-browser > /dev/null ||
  { echo "SKIP: no chromium on PATH (Debian: apt-get install chromium; scripts/install-deps.sh installs it)"; exit 77; }
for tool in pdftoppm pdfimages pdftotext; do
  command -v $tool > /dev/null || { echo "SKIP: no $tool (Debian: apt-get install poppler-utils; scripts/install-deps.sh installs it)"; exit 77; }
done

"$bin" report "$tmp/run" --pdf > "$tmp/stdout" 2> "$tmp/stderr" || { cat "$tmp/stderr"; fail "report --pdf"; }
grep -q "^PDF of the report written to $tmp/run/report.pdf$" "$tmp/stdout" || { cat "$tmp/stdout"; fail "report --pdf does not name the PDF"; }
[ "$(head -c 5 "$tmp/run/report.pdf")" = "%PDF-" ] || fail "report.pdf is not a PDF"
ls "$tmp/run" | grep -q "part-" && fail "a temporary PDF left in the folder"

pdftoppm -gray -r 30 "$tmp/run/report.pdf" "$tmp/page" || fail "pdftoppm"
pdftoppm -png -r 60 -f 1 -l 1 "$tmp/run/report.pdf" "$out/report_pdf_page" || fail "pdftoppm (png)"
pdfimages "$tmp/run/report.pdf" "$tmp/image" && pdfimages -list "$tmp/run/report.pdf" > "$tmp/images.txt" || fail "pdfimages"
pdftotext "$tmp/run/report.pdf" "$tmp/text.txt" || fail "pdftotext"
"$python" - "$tmp" <<'PY' || fail "the PDF's pages (above)"
import glob, os, sys
tmp = sys.argv[1]
def pgm(path):  # binary PGM (P5) or PPM (P6, its first channel): width, height, 8-bit pixels
    data = open(path, "rb").read()
    fields, at = [], 0
    while len(fields) < 4:
        while data[at:at + 1].isspace(): at += 1
        if data[at:at + 1] == b"#":
            at = data.index(b"\n", at)
            continue
        end = at
        while not data[end:end + 1].isspace(): end += 1
        fields.append(data[at:end]); at = end
    assert fields[0] in (b"P5", b"P6"), path
    w, h = int(fields[1]), int(fields[2])
    channels = 3 if fields[0] == b"P6" else 1
    return w, h, data[at + 1:at + 1 + w * h * channels:channels]
problems = []
pages = sorted(glob.glob(os.path.join(tmp, "page-*.pgm")))
if len(pages) < 4: problems.append("%d pages, expected at least 4 (header and animation, time histories, loops, energy)" % len(pages))
for p in pages:
    w, h, px = pgm(p)
    ink = sum(1 for v in px if v < 200) / float(w * h)
    print("%s: %dx%d, %.2f %% ink" % (os.path.basename(p), w, h, 100 * ink))
    if ink < 0.003: problems.append(os.path.basename(p) + " is blank")
# Each chart is a canvas, an image with an alpha mask (smask) in the PDF: drawn means opaque pixels.
listed = [line.split() for line in open(os.path.join(tmp, "images.txt")).read().splitlines()[2:]]
masks = [glob.glob(os.path.join(tmp, "image-%03d.p?m" % int(f[1])))[0] for f in listed if len(f) > 2 and f[2] == "smask"]
drawn = 0
for p in masks:
    w, h, px = pgm(p)
    if w * h and sum(1 for v in px if v > 0) / float(w * h) > 0.01: drawn += 1
print("%d images, %d drawn" % (len(masks), drawn))
# The animation, displacement, velocity, two accelerations, forces, the anticlimber's loop, energy zones, energy partition.
if drawn < 9: problems.append("only %d drawn charts, expected 9" % drawn)
text = open(os.path.join(tmp, "text.txt"), encoding="utf-8", errors="replace").read()
for words in ["railcrash run report", "two cars <script>", "Animation of the planar model", "Time histories",
              "Force-deformation loops", "Energy partition"]:
    if words not in text: problems.append("the text lacks " + repr(words))
if "Play" in text.split("Time histories")[0]: problems.append("the animation's controls are printed")
print("\n".join(problems) if problems else "pdf ok")
sys.exit(1 if problems else 0)
PY
[ -s "$out/report_pdf_page-1.png" ] || fail "no PNG of the first page"
echo "PASS: report --pdf prints the report (first page in $out/report_pdf_page-1.png)"
