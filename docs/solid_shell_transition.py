# Moment-curvature of an elastic-plastic plane-strain strip (small strain, von Mises, Swift
# hardening 500 (0.01 + e_p)^0.22, E = 210 000, nu = 0.3: the material of
# tests/solid_shell_bending.rs), analytic (fibre law integrated by a radial return, moment by
# a 20 001-point rule) against the through-thickness rules of one solid-shell layer (5, 7, 9,
# 11 Newton-Cotes points) and of 8 F-bar layers (2 Gauss points each). Needs numpy.
# Run: python3 docs/solid_shell_transition.py (docs/solid-shell.md quotes its output).
import numpy as np
E,nu=210e3,0.3; C,e0,n=500.0,0.01,0.22
G=E/(2*(1+nu)); K=E/(3*(1-2*nu))
def sy(ep): return C*(e0+ep)**n
def dsy(ep): return C*n*(e0+ep)**(n-1)
# small-strain J2 plane strain fibre: eps_x given, eps_y=0, sigma_z=0 -> solve eps_z. Monotonic loading in increments.
def fibre_curve(emax, N=400):
    # returns function sigma_x(eps) by incremental integration, radial return with eps_z solved by Newton
    eps_grid=np.linspace(0,emax,N+1); sig=[0.0]
    ep=np.zeros(6); a=0.0  # plastic strain tensor voigt (xx,yy,zz), eq plastic
    ez=0.0
    for ex in eps_grid[1:]:
        for it in range(50):
            def stress(ez):
                e=np.array([ex,0.0,ez])-ep[:3]
                tr=e.sum(); dev=e-tr/3
                s_tr=2*G*dev; p=K*tr
                q=np.sqrt(1.5)*np.linalg.norm(s_tr)
                if q>sy(a)*(1+1e-12):
                    # radial return with hardening: solve dg
                    dg=0.0
                    for k in range(60):
                        f=q-3*G*dg-sy(a+dg)
                        dg-= f/(-3*G-dsy(a+dg))
                        if abs(f)<1e-10: break
                    nrm=s_tr/ (np.linalg.norm(s_tr))
                    s=s_tr*(1-3*G*dg/q)
                    return s+p, dg, 1.5*dg*s_tr/q*2/3*1.5/1.5
                return s_tr+p,0.0,None
            sz=stress(ez)[0][2]
            h=1e-9; dz=(stress(ez+h)[0][2]-sz)/h
            ez-=sz/dz
            if abs(sz)<1e-9: break
        s,dg,_=stress(ez)
        if dg>0:
            e=np.array([ex,0.0,ez])-ep[:3]; tr=e.sum(); dev=e-tr/3; s_tr=2*G*dev; q=np.sqrt(1.5)*np.linalg.norm(s_tr)
            ep[:3]+=1.5*dg*s_tr/q
            a+=dg
        sig.append(s[0])
    return eps_grid,np.array(sig)
t=1.0
kmax=0.021
eg,sg=fibre_curve(kmax*t/2,N=3000)
def sx(e): return np.sign(e)*np.interp(abs(e),eg,sg)
def moment(k,zs,ws): return sum(w*sx(k*z)*z for z,w in zip(zs,ws))
# exact: fine
zf=np.linspace(-0.5,0.5,20001); wf=np.full_like(zf,zf[1]-zf[0]); wf[0]*=0.5; wf[-1]*=0.5
# 5-point composite Simpson (halves) on [-1,1] scaled: points -1,-.5,0,.5,1 weights h/3*(1,4,2,4,1) h=.5 -> per half simpson
z5=np.array([-1,-.5,0,.5,1])*0.5; w5=np.array([1,4,2,4,1])/6*0.5*1.0
w5=w5/ w5.sum()*1.0
# 8 layers x 2 gauss
g=1/np.sqrt(3); z16=[];w16=[]
for k in range(8):
    c=-0.5+(k+0.5)/8; h=1/16
    z16+= [c-g*h,c+g*h]; w16+=[h,h]
for R in [400,200,100,50,20,10]:
    k=1/(R*t)
    if k>kmax: continue
    me=moment(k,zf,wf); m5=moment(k,z5,w5); m16=moment(k,z16,w16)
    print(f"R={R}t kappa={k:.4f}: analytic {me:.4f}  5-pt Simpson {m5:.4f} ({100*(m5/me-1):+.2f}%)  8x2 Gauss {m16:.4f} ({100*(m16/me-1):+.2f}%)  5pt vs 16pt {100*(m5/m16-1):+.2f}%")

def nc_rule(n):
    # the element's thickness_rule for odd n >= 5 (src/element/solid_shell.rs), on [-1, 1]
    m=(n-1)//2; h=1.0/m; half=[0.0]*(m+1)
    simpson = m if m%2==0 else m-3
    for i in range(0,simpson,2):
        half[i]+=h/3; half[i+1]+=4*h/3; half[i+2]+=h/3
    if simpson<m:
        for k,c in enumerate([1,3,3,1]): half[simpson+k]+=3*h/8*c
    x=[-1+i*h for i in range(n)]; w=[0.0]*n
    for i,wi in enumerate(half):
        w[m+i]+=wi; w[m-i]+=wi
    return np.array(x)*0.5, np.array(w)*0.5
print("thickness points needed: moment error against the analytic curve, per cent")
for npts in [5,7,9,11]:
    z,w=nc_rule(npts)
    errs=[]
    for R in [400,200,100,50,20]:
        k=1/R
        if k>kmax: continue
        errs.append(f"R={R}t {100*(moment(k,z,w)/moment(k,zf,wf)-1):+.2f}")
    print(npts, ", ".join(errs))

# Worst moment error over R = 5 t ... 3000 t (160 radii) by rule and count: Newton-Cotes per
# half (the element's odd rule), Gauss-Legendre, Gauss and Lobatto on each half. Only the
# count matters in the transition (the kinks at the elastic core's edges fall inside panels).
from numpy.polynomial import legendre as L
eg,sg=fibre_curve(0.21*t/2,N=3000)
def gl(n):
    x,w=L.leggauss(n); return x*0.5,w*0.5
def lobatto(n):
    c=np.zeros(n); c[-1]=1
    x=np.concatenate([[-1],L.legroots(L.legder(c)),[1]]); P=L.legval(x,c)
    return x*0.5,(2/(n*(n-1)*P**2))*0.5
def split(rule1,m):
    x,w=rule1(m); d={}
    for off in (-0.25,0.25):
        for a,b in zip(x*0.5+off,w*0.5): d[round(a,14)]=d.get(round(a,14),0)+b
    k=sorted(d); return np.array(k),np.array([d[a] for a in k])
Rs=np.geomspace(5,3000,160)
ref={R:moment(1/R,zf,wf) for R in Rs}
def worst(z,w,only=None):
    errs=[(abs(moment(1/R,z,w)/ref[R]-1),R) for R in Rs if only is None or R<=only]
    return max(errs)
print("worst moment error over R = 5 t ... 3000 t, per cent (at R), and for R <= 50 t")
for name,rule,ns in [("Newton-Cotes per half",nc_rule,[5,7,9,11,13]),("Gauss-Legendre",gl,[5,6,8,10,12]),
                     ("Gauss per half",lambda m: split(gl,m),[3,4,5,6]),("Lobatto per half",lambda m: split(lobatto,m),[4,5,6,7])]:
    for n in ns:
        z,w=rule(n); e,R=worst(z,w); e50,_=worst(z,w,50)
        print(f"{name}, {len(z)} points: {100*e:.2f} % (R = {R:.0f} t); R <= 50 t: {100*e50:.2f} %")
