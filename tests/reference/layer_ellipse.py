"""Reference values for core/src/hardness/layer_compliance.rs: the centre displacement of a bonded layer
under an elliptical Hertz pressure relative to the half-space, integrated numerically over the
wavevector plane (polar k, phi) with scipy, without the circular reduction the Rust code uses.

    python3 tests/reference/layer_ellipse.py
"""
import numpy as np
from scipy import integrate
def K(kh, nu):
    th=np.tanh(kh); sech2=1/np.cosh(kh)**2
    return ((3-4*nu)*th-kh*sech2)/(kh*kh*sech2+4*(1-nu)**2-(1-2*nu)**2*th*th)
def j1x(q):  # FT of the unit disc's sqrt(1-r^2) over 2 pi: (sin q - q cos q)/q^3
    return (np.sin(q)-q*np.cos(q))/q**3 if q>1e-4 else 1/3
def ratio(a,b,nu):
    h=1.0
    def inner(phi, layer):
        s=np.hypot(a*np.cos(phi), b*np.sin(phi))
        f=lambda k: a*b*j1x(k*s)*((1-K(k*h,nu)) if layer else 1.0)
        top = 40.0 if layer else 4000/s
        v,_=integrate.quad(f,0,top,limit=4000)
        if not layer: v += a*b/s**2*(np.cos(top*s)/(top*s))  # tail ~ -cos(x)/x^2 integral
        return v
    num,_=integrate.quad(lambda p: inner(p,True),0,np.pi/2,limit=200)
    den,_=integrate.quad(lambda p: inner(p,False),0,np.pi/2,limit=200)
    return 1-num/den
for a,b,nu in [(2.0,0.5,0.49),(1.0,0.25,0.49),(3.0,1.0,0.45),(1.5,1.5,0.49)]:
    print(a,b,nu,repr(ratio(a,b,nu)))
