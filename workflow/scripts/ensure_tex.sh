#!/usr/bin/env bash
# Make sure the TeX tools the paper stage needs (latexmk, pdflatex) are present.
# Present: exit 0. Missing and we are root on a Debian-like system: install the Debian
# packages below. Otherwise: print ONE line naming what to install, exit 1.
set -u
PKGS="texlive-latex-recommended texlive-fonts-recommended texlive-latex-extra latexmk"

have() { command -v "$1" >/dev/null 2>&1; }

if have latexmk && have pdflatex; then
    exit 0
fi

if [ "$(id -u)" = 0 ] && have apt-get; then
    echo "ensure_tex: installing $PKGS (about 150 MB)" >&2
    export DEBIAN_FRONTEND=noninteractive
    if apt-get update -qq >&2 && apt-get install -y -qq --no-install-recommends $PKGS >&2 \
        && have latexmk && have pdflatex; then
        exit 0
    fi
    echo "error: installing TeX failed; install the Debian packages: $PKGS" >&2
    exit 1
fi

echo "error: latexmk and pdflatex are required for the paper; install the Debian packages: sudo apt-get install $PKGS" >&2
exit 1
