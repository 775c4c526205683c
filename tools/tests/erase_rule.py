"""The host's rule around page erases (docs/reliability.md): a request that
lands in a servo's 40 ms page erase is carried out but not answered, so
after 0.1 s of quiet on a bus with a released servo, a request without an
answer is sent again. A test host that a loaded PC pauses for 0.1 s of
simulated time meets it, as any host would."""
from servoctl import protocol as p


def again_if_unanswered(request):
    """request() once more if its answer did not come."""
    try:
        return request()
    except p.NoReply:
        return request()
