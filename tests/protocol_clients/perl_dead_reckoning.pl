#!/usr/bin/perl
# perl_dead_reckoning.pl -- a minimal olp/1 client (omniloc localizer protocol),
# written from docs/protocol.md alone, using core Perl modules only.
#
# It answers `hello` with `ready`, takes the start pose from `reset`, and on every
# `frame` dead-reckons from the odometry with the spec's formula (section 5, `frame`):
#     x += dx cos th - dy sin th;  y += dx sin th + dy cos th;  th += dtheta
# and answers an `estimate` (valid, mode "dead_reckoning") with two extra numbers:
# `line_points` (count of line points) and, when images are requested
# (environment OLP_WANTS_IMAGE=1), `image_mean` (mean of all image bytes).
#
# Exit status: 0 after `end`; 1 on end-of-file or a protocol error; 2 when the
# host speaks another protocol than olp/1. Diagnostics go to stderr only.
use strict;
use warnings;
use B ();
use IO::Handle ();
use JSON::PP ();

my $NAME        = 'perl_dead_reckoning';
my $VERSION     = '1.0';
my $WANTS_IMAGE = (defined $ENV{OLP_WANTS_IMAGE} && $ENV{OLP_WANTS_IMAGE} eq '1') ? 1 : 0;

# Raw byte pipes (section 3): no CRLF or :utf8 layers, whatever PERL_UNICODE says.
binmode(STDIN)  or die "binmode STDIN: $!";
binmode(STDOUT) or die "binmode STDOUT: $!";
binmode(STDERR);

my $json = JSON::PP->new->utf8;    # input lines are UTF-8 bytes

sub diag { print STDERR "$NAME: ", @_, "\n"; }
sub fail { my ($status, @msg) = @_; diag(@msg); exit $status; }

# ---- numbers -------------------------------------------------------------
# A JSON number (as JSON::PP decodes it: an IV or NV, not a string). Call it
# before the value is ever stringified.
sub is_number {
    return 0 if !defined($_[0]) || ref($_[0]);
    my $f = B::svref_2object(\$_[0])->FLAGS;
    return (($f & (B::SVp_IOK | B::SVp_NOK)) && !($f & B::SVp_POK)) ? 1 : 0;
}

sub is_finite { my ($v) = @_; return ($v == $v && $v != 9**9**9 && $v != -9**9**9) ? 1 : 0; }

# A double with 17 significant digits: reads back exactly (never NaN/Infinity).
sub num {
    my ($v) = @_;
    fail(1, "refusing to send a non-finite number ($v)") unless is_finite($v);
    my $s = sprintf('%.17g', $v);
    return $s;
}

# ---- I/O -------------------------------------------------------------------
# Write one message line and flush it at once (section 3).
sub send_line {
    my ($line) = @_;
    print STDOUT $line, "\n" or fail(1, "write to stdout failed: $!");
    STDOUT->flush             or fail(1, "flush of stdout failed: $!");
}

# Read exactly $n bytes, looping on short reads (section 3 / 9).
sub read_exact {
    my ($n) = @_;
    my $buf = '';
    while (length($buf) < $n) {
        my $got = read(STDIN, $buf, $n - length($buf), length($buf));
        fail(1, "read error inside a binary part: $!") unless defined $got;
        fail(1, "end-of-file inside a binary part (" . length($buf) . " of $n bytes)") if $got == 0;
    }
    return $buf;
}

# Read the next message: one JSON object on one line, then its binary parts.
# Returns ($msg, { name => bytes, ... }); exits non-zero on end-of-file.
sub read_message {
    while (1) {
        my $line = readline(STDIN);
        unless (defined $line) {
            fail(1, "read error on stdin: $!") if STDIN->error;
            fail(1, "end-of-file on stdin before end");
        }
        fail(1, "end-of-file in the middle of a line") unless $line =~ s/\n\z//;
        $line =~ s/\r\z//;
        if ($line =~ /\A[ \t]*\z/) { diag("ignoring an empty line"); next; }
        my $msg = eval { $json->decode($line) };
        fail(1, "not a JSON message: $@ (line: " . substr($line, 0, 200) . ")") unless defined $msg;
        fail(1, "not a JSON object: " . substr($line, 0, 200)) unless ref($msg) eq 'HASH';
        fail(1, "message without a string \"type\"")
            unless defined $msg->{type} && !ref($msg->{type});

        my %parts;
        if (exists $msg->{binary} && defined $msg->{binary}) {
            my $list = $msg->{binary};
            fail(1, "$msg->{type}: /binary: expected an array") unless ref($list) eq 'ARRAY';
            my $i = 0;
            for my $p (@$list) {
                fail(1, "$msg->{type}: /binary/$i: expected an object") unless ref($p) eq 'HASH';
                my $bytes = $p->{bytes};
                fail(1, "$msg->{type}: /binary/$i/bytes: expected a non-negative integer")
                    unless is_number($bytes) && $bytes == int($bytes) && $bytes >= 0;
                if (ref($p->{shape}) eq 'ARRAY' && defined $p->{dtype} && $p->{dtype} eq 'uint8') {
                    my $prod = 1;
                    $prod *= $_ for @{ $p->{shape} };
                    diag("warning: /binary/$i: bytes $bytes != product of shape $prod") if $prod != $bytes;
                }
                my $data = read_exact($bytes);    # always consume the bytes, even of unknown parts
                my $name = defined $p->{name} ? $p->{name} : "part$i";
                $parts{$name} = { spec => $p, data => $data };
                $i++;
            }
        }
        return ($msg, \%parts);
    }
}

# Mean of all bytes of a string, summed in chunks so a 32-bit checksum never overflows.
sub byte_mean {
    my ($data) = @_;
    my $n = length($data);
    return 0 if $n == 0;
    my $sum = 0;
    my $CHUNK = 1 << 20;    # 2^20 * 255 < 2^32
    for (my $off = 0; $off < $n; $off += $CHUNK) {
        $sum += unpack('%32C*', substr($data, $off, $CHUNK));
    }
    return $sum / $n;
}

# ---- the protocol ----------------------------------------------------------
# hello -> ready
my ($hello) = read_message();
fail(1, "expected hello, got $hello->{type}") unless $hello->{type} eq 'hello';
my $proto = defined $hello->{protocol} ? $hello->{protocol} : '(none)';
fail(2, "host speaks $proto, this client speaks olp/1 only") unless $proto eq 'olp/1';
diag("hello from omniloc " . (defined $hello->{omniloc} ? $hello->{omniloc} : '?')
     . ", robot " . (defined $hello->{robot} ? $hello->{robot} : '?')
     . ", wants_image " . ($WANTS_IMAGE ? 'true' : 'false'));
send_line(sprintf('{"type":"ready","protocol":"olp/1","name":"%s","version":"%s",'
                . '"needs_start_pose":true,"wants_image":%s}',
                  $NAME, $VERSION, $WANTS_IMAGE ? 'true' : 'false'));

my ($x, $y, $th) = (0, 0, 0);
my $have_reset = 0;
my $next_k     = 0;

while (1) {
    my ($msg, $parts) = read_message();
    my $type = $msg->{type};

    if ($type eq 'reset') {
        my $start = $msg->{start};
        if (ref($start) eq 'ARRAY' && @$start == 3 && !grep { !is_number($_) } @$start) {
            ($x, $y, $th) = map { 0 + $_ } @$start;
        } else {
            diag("warning: reset without a usable start pose; dead-reckoning from (0, 0, 0)");
            ($x, $y, $th) = (0, 0, 0);
        }
        $have_reset = 1;
        $next_k     = 0;
        diag("reset: seed " . (defined $msg->{seed} ? $msg->{seed} : '?')
             . ", start [" . join(', ', map { num($_) } $x, $y, $th) . "]");
    }
    elsif ($type eq 'frame') {
        fail(1, "frame before reset") unless $have_reset;
        my $k = $msg->{k};
        fail(1, "frame: /k: expected a non-negative integer")
            unless is_number($k) && $k == int($k) && $k >= 0;
        diag("warning: frame k=$k, expected $next_k") if $k != $next_k;
        $next_k = $k + 1;

        my $odo = $msg->{odometry};
        fail(1, "frame $k: /odometry: expected [dx, dy, dtheta]")
            unless ref($odo) eq 'ARRAY' && @$odo == 3 && !grep { !is_number($_) } @$odo;
        my ($dx, $dy, $dth) = @$odo;
        # The spec's formula: th is the heading of the previous frame for both x and y, evaluated
        # left to right (revised spec, see NOTES.md "After the first review").
        my ($c, $s) = (cos($th), sin($th));
        $x  = $x + $c * $dx - $s * $dy;
        $y  = $y + $s * $dx + $c * $dy;
        $th += $dth;

        my $lp = $msg->{line_points};
        my $n_lp = ref($lp) eq 'ARRAY' ? scalar(@$lp) : 0;
        my @extra = ('"n_line_points":' . $n_lp);
        if ($WANTS_IMAGE) {
            my $img = $parts->{image};
            if ($img) {
                push @extra, '"image_mean":' . num(byte_mean($img->{data}));
            } else {
                diag("warning: frame $k has no image part although wants_image was true");
            }
        }
        send_line(sprintf('{"type":"estimate","k":%.0f,"pose":[%s,%s,%s],"valid":true,'
                        . '"mode":"dead_reckoning","extra":{%s}}',
                          $k, num($x), num($y), num($th), join(',', @extra)));
    }
    elsif ($type eq 'end') {
        diag("end after $next_k frames");
        exit 0;
    }
    elsif ($type eq 'hello') {
        fail(1, "a second hello");
    }
    else {
        # olp/1 has no other host messages; ignore unknown ones (their binary parts are already consumed).
        diag("warning: ignoring a message of unknown type '$type'");
    }
}
