#!/usr/bin/env python3
"""Compares two screenshots of one size (`meshslim view --screenshot`), with no packages beyond
Python's own: how many pixels differ by more than TOL (of 255) in a channel, how many each drew
(not the first pixel's background), and where the first shows background and the second drew.
With OUT.png, also writes the two side by side (the second on the left), cropped to what they
drew.

    python3 benches/png_diff.py dag.png full.png 16 [side-by-side.png]
"""
import zlib,struct,sys
def read(p):
    b=open(p,'rb').read(); assert b[:8]==b'\x89PNG\r\n\x1a\n'
    i=8; idat=b''; w=h=0
    while i<len(b):
        n,=struct.unpack('>I',b[i:i+4]); t=b[i+4:i+8]; d=b[i+8:i+8+n]; i+=12+n
        if t==b'IHDR': w,h,bd,ct=struct.unpack('>IIBB',d[:10]); assert bd==8; bpp={6:4,2:3}[ct]
        elif t==b'IDAT': idat+=d
    raw=zlib.decompress(idat); stride=w*bpp; out=bytearray(); prev=bytearray(stride)
    for y in range(h):
        f=raw[y*(stride+1)]; line=bytearray(raw[y*(stride+1)+1:(y+1)*(stride+1)])
        for x in range(stride):
            a=line[x-bpp] if x>=bpp else 0; up=prev[x]; c=prev[x-bpp] if x>=bpp else 0
            if f==1: line[x]=(line[x]+a)&255
            elif f==2: line[x]=(line[x]+up)&255
            elif f==3: line[x]=(line[x]+((a+up)>>1))&255
            elif f==4:
                p_=a+up-c; pa,pb,pc=abs(p_-a),abs(p_-up),abs(p_-c)
                pr=a if pa<=pb and pa<=pc else (up if pb<=pc else c); line[x]=(line[x]+pr)&255
        out+=line; prev=line
    return w,h,bpp,out
w,h,bpp,a=read(sys.argv[1]); w2,h2,bpp2,b=read(sys.argv[2]); assert (w,h,bpp)==(w2,h2,bpp2)
tol=int(sys.argv[3]) if len(sys.argv)>3 else 0
bg=tuple(a[0:3])
n=w*h; diff=0; sil_a=sil_b=0; hole=0
for i in range(n):
    pa=a[i*bpp:i*bpp+3]; pb=b[i*bpp:i*bpp+3]
    if max(abs(pa[k]-pb[k]) for k in range(3))>tol: diff+=1
    ia=tuple(pa)!=bg; ib=tuple(pb)!=bg
    sil_a+=ia; sil_b+=ib
    if ib and not ia: hole+=1
print(f"{w}x{h}: pixels differing by more than {tol}: {diff} ({100*diff/n:.3f}%); drawn {sil_a} vs {sil_b}; background in the first where the second drew: {hole}")

def write(path, w, h, rgb_rows):
    raw=b''.join(b'\x00'+bytes(r) for r in rgb_rows)
    def chunk(t,d): return struct.pack('>I',len(d))+t+d+struct.pack('>I',zlib.crc32(t+d)&0xffffffff)
    png=b'\x89PNG\r\n\x1a\n'+chunk(b'IHDR',struct.pack('>IIBBBBB',w,h,8,2,0,0,0))+chunk(b'IDAT',zlib.compress(raw,9))+chunk(b'IEND',b'')
    open(path,'wb').write(png)

if len(sys.argv)>4:
    # side by side, cropped to the drawn box plus a margin: the second (full) on the left
    xs=[];ys=[]
    for i in range(n):
        if tuple(a[i*bpp:i*bpp+3])!=bg or tuple(b[i*bpp:i*bpp+3])!=bg: xs.append(i%w); ys.append(i//w)
    m=12; x0=max(min(xs)-m,0); x1=min(max(xs)+m,w-1); y0=max(min(ys)-m,0); y1=min(max(ys)+m,h-1)
    cw=x1-x0+1; rows=[]
    for y in range(y0,y1+1):
        r=bytearray()
        for img in (b,a):
            for x in range(x0,x1+1):
                i=(y*w+x)*bpp; r+=img[i:i+3]
        rows.append(r)
    write(sys.argv[4], 2*cw, y1-y0+1, rows)
    print('wrote', sys.argv[4], 2*cw, y1-y0+1)
