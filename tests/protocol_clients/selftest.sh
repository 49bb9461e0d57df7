#!/bin/sh
# selftest.sh -- checks perl_dead_reckoning.pl against hand-made olp/1 message
# streams (docs/protocol.md), without omniloc. Exit status 0 when all checks pass.
#
# Cases:
#   image     OLP_WANTS_IMAGE=1: hello, reset, frame 0 and frame 1 each with an
#             "image" part of shape [2,2,3] (bytes include 0x0A, '{' and '}'), end
#   trickle   the same stream written a few bytes at a time (partial reads)
#   noimage   OLP_WANTS_IMAGE unset: no binary parts
#   eof       the noimage stream without `end`: the client must exit non-zero
#   protocol  hello.protocol "olp/2": the client must exit non-zero
set -u
here=$(cd "$(dirname "$0")" && pwd)
client="$here/perl_dead_reckoning.pl"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/olp_selftest.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
failures=0

# ---- the stream builder: writes a message stream to stdout -----------------
cat > "$tmp/host.pl" <<'PERL'
use strict; use warnings;
my ($with_image, $with_end, $trickle, $protocol) = @ARGV;
binmode STDOUT;
my @img = ([0 .. 11], [255, 10, 13, 123, 125, 0, 1, 2, 3, 4, 5, 6]);   # 2x2x3 each
my $part = '"binary":[{"name":"image","dtype":"uint8","shape":[2,2,3],"bytes":12}]';
my $out = '';
$out .= qq({"type":"hello","protocol":"$protocol","omniloc":"selftest","robot":0,)
      . qq("scenario":"selftest","camera_rate_hz":30,"duration_s":0.05,)
      . qq("hello_timeout_s":60,"frame_timeout_s":10,"exit_timeout_s":5,"params":{},)
      . qq("field":{"name":"msl2012","length":18,"width":12,"margin":1,"line_width":0.125,)
      . qq("segments":[],"arcs":[],"spots":[],"goals":[],"goal_colours":[],"landmarks":[]},)
      . qq("camera":{"width":2,"height":2,"channels":3,"layout":"HWC","mirror_centre_px":[1,1]},)
      . qq("vision":{"line_points":true,"blobs":false},"a_future_field":{"x":[1,2,3]}}\n);
$out .= qq({"type":"reset","seed":4049918117441,"start":[0.5,-1.5,0.69999999999999996]}\n);
$out .= qq({"type":"frame","k":0,"t":0.0,"odometry":[0,0,0],"heading":null,"camera_ok":false,)
      . qq("line_points":[],"blobs":[]) . ($with_image ? ",$part" : '') . "}\n";
$out .= pack('C*', @{ $img[0] }) if $with_image;
$out .= qq({"type":"frame","k":1,"t":0.033333333333333333,"odometry":[0.1,0.02,0.05],)
      . qq("heading":0.75,"camera_ok":true,"line_points":[[1.204,-0.331],[2.5,0.75]],)
      . qq("blobs":[],"unknown_field":"ignored") . ($with_image ? ",$part" : '') . "}\n";
$out .= pack('C*', @{ $img[1] }) if $with_image;
$out .= qq({"type":"end"}\n) if $with_end;
if ($trickle) {
    my $i = 0;
    while ($i < length $out) {
        my $n = 1 + ($i % 5);
        syswrite(STDOUT, substr($out, $i, $n)) or last;
        $i += $n;
        select(undef, undef, undef, 0.002);
    }
} else {
    print STDOUT $out;
}
PERL

# ---- the checker: reads the client's stdout --------------------------------
cat > "$tmp/check.pl" <<'PERL'
use strict; use warnings; use JSON::PP;
my ($file, $with_image) = @ARGV;
open(my $fh, '<:raw', $file) or die "$file: $!";
my @lines = <$fh>;
my $bad = 0;
sub bad { print "  FAIL: @_\n"; $bad++; }
bad("expected 3 lines, got " . scalar(@lines)) unless @lines == 3;
my @msg;
for my $i (0 .. $#lines) {
    bad("line $i does not end with \\n") unless $lines[$i] =~ /\n\z/;
    my $m = eval { JSON::PP->new->utf8->decode($lines[$i]) };
    if (ref($m) ne 'HASH') { bad("line $i is not a JSON object: $lines[$i]"); $m = {}; }
    push @msg, $m;
}
my $r = $msg[0] || {};
bad("first message is not ready") unless ($r->{type} // '') eq 'ready';
bad("ready.name") unless ($r->{name} // '') eq 'perl_dead_reckoning';
bad("ready.version") unless ($r->{version} // '') eq '1.0';
bad("ready.needs_start_pose") unless JSON::PP::is_bool($r->{needs_start_pose}) && $r->{needs_start_pose};
bad("ready.wants_image") unless JSON::PP::is_bool($r->{wants_image}) && (!!$r->{wants_image}) == (!!$with_image);
bad("ready.protocol") if defined $r->{protocol} && $r->{protocol} ne 'olp/1';
# Expected poses (computed independently with Python's float arithmetic).
my @pose = ([0.5, -1.5, 0.69999999999999996],
            [0.56359986498369508, -1.4202813875305411, 0.75]);
my @n_lp = (0, 2);
my @mean = (5.5, 547 / 12);
for my $k (0, 1) {
    my $e = $msg[$k + 1] || {};
    bad("message $k+1 is not an estimate") unless ($e->{type} // '') eq 'estimate';
    bad("estimate $k: k is " . ($e->{k} // 'missing')) unless defined $e->{k} && $e->{k} == $k;
    bad("estimate $k: valid") unless JSON::PP::is_bool($e->{valid}) && $e->{valid};
    bad("estimate $k: mode") unless ($e->{mode} // '') eq 'dead_reckoning';
    my $p = $e->{pose};
    if (ref($p) ne 'ARRAY' || @$p != 3) { bad("estimate $k: pose missing"); }
    else {
        for my $i (0 .. 2) {
            bad(sprintf("estimate %d: pose[%d] = %.17g, expected %.17g", $k, $i, $p->[$i], $pose[$k][$i]))
                unless $p->[$i] == $pose[$k][$i];
        }
    }
    my $x = $e->{extra} || {};
    bad("estimate $k: extra.n_line_points") unless defined $x->{n_line_points} && $x->{n_line_points} == $n_lp[$k];
    if ($with_image) {
        bad("estimate $k: extra.image_mean = " . ($x->{image_mean} // 'missing') . ", expected $mean[$k]")
            unless defined $x->{image_mean} && $x->{image_mean} == $mean[$k];
    } else {
        bad("estimate $k: extra.image_mean present without images") if exists $x->{image_mean};
    }
}
exit($bad ? 1 : 0);
PERL

# run NAME WITH_IMAGE WITH_END TRICKLE PROTOCOL EXPECT(ok|fail)
run() {
    name=$1; img=$2; end=$3; trickle=$4; proto=$5; expect=$6
    if [ "$img" = 1 ]; then wants=1; else wants=0; fi
    perl "$tmp/host.pl" "$img" "$end" "$trickle" "$proto" \
        | OLP_WANTS_IMAGE=$wants "$client" >"$tmp/$name.out" 2>"$tmp/$name.err"
    status=$?
    ok=1
    if [ "$expect" = ok ]; then
        if [ $status -ne 0 ]; then echo "  FAIL: exit status $status, expected 0"; ok=0; fi
        perl "$tmp/check.pl" "$tmp/$name.out" "$img" || ok=0
    else
        if [ $status -eq 0 ]; then echo "  FAIL: exit status 0, expected non-zero"; ok=0; fi
    fi
    if [ $ok = 1 ]; then
        echo "ok   $name (exit $status)"
    else
        echo "FAIL $name (exit $status); client stdout:"; sed 's/^/    /' "$tmp/$name.out"
        echo "  client stderr:"; sed 's/^/    /' "$tmp/$name.err"
        failures=$((failures + 1))
    fi
}

run image    1 1 0 olp/1 ok
run trickle  1 1 1 olp/1 ok
run noimage  0 1 0 olp/1 ok
run eof      0 0 0 olp/1 fail
run protocol 0 1 0 olp/2 fail

if [ $failures -ne 0 ]; then echo "selftest: $failures case(s) failed"; exit 1; fi
echo "selftest: all cases passed"
